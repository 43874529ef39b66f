#include "apps/exit_status.h"

#include <filesystem>
#include <new>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace parallax {

ExitStatus ExitStatusOf(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const UsageError& usage) {
    return {kExitUsage, usage.what()};
  } catch (const BadInputError& bad_input) {
    return {kExitBadInput, bad_input.what()};
  } catch (const std::filesystem::filesystem_error& filesystem) {
    // A path the user named cannot be read or written; the message names it.
    return {kExitBadInput, filesystem.what()};
  } catch (const nlohmann::json::exception& json) {
    // JSON comes from files: a scene description, a report, a stage cache.
    return {kExitBadInput, "malformed JSON: " + std::string(json.what())};
  } catch (const ToolError& tool) {
    return {kExitToolFailed, tool.what()};
  } catch (const std::bad_alloc&) {
    return {kExitInternal, "out of memory"};
  } catch (const std::exception& other) {
    // Not the user's input and not an external tool: a bug, or the machine (GL, Embree).
    return {kExitInternal, "internal error: " + std::string(other.what()) +
                               " (please report it with the command line)"};
  } catch (...) {
    return {kExitInternal, "internal error: an unknown exception (please report it with the command line)"};
  }
}

}  // namespace parallax
