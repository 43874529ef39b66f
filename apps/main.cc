// parallax: photos -> cameras, depth, novel views and a shadowed viewer. See README.md.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/exit_status.h"
#include "core/interrupt.h"

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
  } catch (...) {
    const ExitStatus status = ExitStatusOf(std::current_exception());
    std::fflush(stdout);
    std::fprintf(stderr, "error: %s\n", status.message.c_str());
    return status.code;
  }
  return 0;
}
