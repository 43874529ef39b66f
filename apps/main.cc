// parallax: photos -> cameras, depth, novel views and a shadowed viewer. See README.md.
#include <cstdio>
#include <exception>
#include <stdexcept>

#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/interrupt.h"

namespace parallax {
namespace {

// Exit codes of docs/design.md.
constexpr int kExitUsage = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitToolFailed = 3;

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
  } catch (const std::exception& error) {
    return PrintError(error.what(), kExitBadInput);
  }
  return 0;
}
