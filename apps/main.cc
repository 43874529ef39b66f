// parallax: photos -> cameras, depth, novel views and a shadowed viewer. See README.md.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/interrupt.h"

namespace parallax {
namespace {

// Exit codes of docs/design.md.
constexpr int kExitUsage = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitToolFailed = 3;
constexpr int kExitInternal = 4;

int PrintError(const char* message, int code) {
  std::fflush(stdout);
  std::fprintf(stderr, "error: %s\n", message);
  return code;
}

}  // namespace

}  // namespace parallax

int main(int argc, char** argv) {
  using namespace parallax;
  InstallInterruptHandler();
  CLI::App app(
      "parallax: image-based modeling and reprojection.\n"
      "Photos -> COLMAP cameras -> CPU multi-view stereo depth -> novel views by depth-image "
      "warping, with a shadowed OpenGL viewer; synthetic scenes carry ground truth.",
      "parallax");
  app.require_subcommand(1);
  RegisterSynthCommand(app);
  RegisterReconstructCommand(app);
  RegisterRenderCommand(app);
  RegisterEvaluateCommand(app);
  RegisterViewCommand(app);
  RegisterBenchCommand(app);
  RegisterDepthBlockCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    app.exit(error);
    return kExitUsage;
  } catch (const BadInputError& error) {
    return PrintError(error.what(), kExitBadInput);
  } catch (const ToolError& error) {
    return PrintError(error.what(), kExitToolFailed);
  } catch (const std::invalid_argument& error) {
    return PrintError(error.what(), kExitUsage);
  } catch (const std::filesystem::filesystem_error& error) {
    // A path the user named cannot be read or written; the message names it.
    return PrintError(error.what(), kExitBadInput);
  } catch (const nlohmann::json::exception& error) {
    // JSON comes from files: a scene description, a report, a stage cache.
    return PrintError(("malformed JSON: " + std::string(error.what())).c_str(), kExitBadInput);
  } catch (const std::bad_alloc&) {
    return PrintError("out of memory", kExitInternal);
  } catch (const std::exception& error) {
    // Not the user's input and not an external tool: a bug, or the machine (GL, Embree).
    return PrintError(("internal error: " + std::string(error.what()) +
                       " (please report it with the command line)").c_str(),
                      kExitInternal);
  }
  return 0;
}
