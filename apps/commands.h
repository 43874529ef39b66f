#pragma once
// One function per subcommand: adds it to the CLI with its options and the callback that runs
// it. Callbacks throw parallax's exceptions; main() maps them to exit codes.
#include <CLI/CLI.hpp>

namespace parallax {

void RegisterSynthCommand(CLI::App& app);
void RegisterReconstructCommand(CLI::App& app);
void RegisterEvaluateCommand(CLI::App& app);
void RegisterRenderCommand(CLI::App& app);
void RegisterBenchCommand(CLI::App& app);
void RegisterDepthBlockCommand(CLI::App& app);
void RegisterViewCommand(CLI::App& app);

}  // namespace parallax
