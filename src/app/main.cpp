// plenoptic — physically based global illumination with precomputed light fields.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "plenoptic_version.h"  // generated at build time (cmake/version.cmake)

namespace {

/// Refuses NaN, infinities and values beyond the float range (1e39 would become an infinity
/// in a float option) up front, with "OPTION: expected a finite number, got 'nan'". CLI11's
/// Range and PositiveNumber checks let NaN through (every comparison with it is false).
const CLI::Validator kFiniteNumber(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end == text.c_str()) return {};  // not a number at all: CLI11's conversion reports it
      if (!std::isfinite(value) || std::abs(value) > double(std::numeric_limits<float>::max()))
        return "expected a finite number, got '" + text + "'";
      return {};
    },
    "");

/// Adds kFiniteNumber to every floating-point option of `app` and its subcommands, however
/// deep (CLI11 names their type FLOAT), so that no float flag, present or future, can take NaN.
void requireFiniteFloats(CLI::App& app) {
  for (CLI::Option* option : app.get_options())
    if (option->get_type_name().rfind("FLOAT", 0) == 0) option->check(kFiniteNumber);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) requireFiniteFloats(*sub);
}

/// "plenoptic trace" (or "plenoptic env convert"): the subcommands selected so far, for the
/// hint after a usage error.
std::string selectedCommand(const CLI::App& app) {
  std::string name = "plenoptic";
  const CLI::App* current = &app;
  while (!current->get_subcommands().empty()) {
    current = current->get_subcommands().front();
    name += " " + current->get_name();
  }
  return name;
}

/// Prints "plenoptic: error: MESSAGE" to stderr and returns `status`.
int report(const std::string& message, int status) {
  std::fflush(stdout);
  fmt::print(stderr, "plenoptic: error: {}\n", message);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  pl::installInterruptHandlers();

  CLI::App app{"plenoptic: physically based global illumination, precomputed as a light field over the "
               "scene's surfaces and rendered in real time",
               "plenoptic"};
  app.formatter(std::make_shared<pl::cli::HelpFormatter>());  // before the subcommands: they share it
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand name
  app.set_version_flag("--version", "plenoptic " PLENOPTIC_VERSION_STRING);

  pl::GlobalOptions global;
  app.add_option("--threads", global.threads, "Worker threads (0 = all hardware threads)")
      ->check(CLI::Range(0, 4096));
  app.add_option("--seed", global.seed, "Base seed of all random streams");
  app.add_flag("--quiet", global.quiet, "No progress bars");

  // Subcommands in pipeline order. Each one's callback does the work, starting with a
  // pl::Runtime (thread pool, progress settings).
  // (one line per subcommand; keep this list in pipeline order)
  pl::addDemoCommand(app, global);
  pl::addTraceCommand(app, global);
  pl::addBakeCommand(app, global);
  pl::addInfoCommand(app, global);
  pl::addRenderCommand(app, global);
  pl::addViewCommand(app, global);
  pl::addCompareCommand(app, global);
  pl::addTonemapCommand(app, global);
  pl::addEnvCommand(app, global);
  pl::addCompressCommand(app, global);
  pl::cli::addGeneratorCommands(app, PLENOPTIC_VERSION_STRING);  // hidden: completion bash, manpage
  requireFiniteFloats(app);
  pl::cli::groupCommands(app);

  // No arguments (or only a command that needs a subcommand, as `env`): the command list.
  if (const CLI::App* command = pl::cli::commandListRequested(app, std::vector<std::string>(argv + 1, argv + argc))) {
    std::string parents;
    for (const CLI::App* parent = command->get_parent(); parent != nullptr; parent = parent->get_parent())
      parents = parent->get_name() + (parents.empty() ? "" : " " + parents);
    std::cout << command->help(parents) << std::flush;
    return pl::kExitSuccess;
  }

  // One error form for every failure: "plenoptic: error: ..." on stderr and the exit
  // statuses of core/error.h (1 the command failed, 2 the command line is wrong; 130/143
  // when interrupted, core/interrupt.h). --help and --version print to stdout and exit 0.
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // An unknown command or option: name the nearest known one ("did you mean 'trace'?").
    if (const auto unknown = pl::cli::unknownArgumentMessage(app))
      return report(fmt::format("{} (see '{} --help')", *unknown, selectedCommand(app)), pl::kExitUsage);
    if (const auto missing = pl::cli::missingCommandMessage(app, e))
      return report(fmt::format("{} (see '{} --help')", *missing, selectedCommand(app)), pl::kExitUsage);
    return report(fmt::format("{} (see '{} --help')", pl::cli::parseErrorMessage(e.what()), selectedCommand(app)),
                  pl::kExitUsage);
  } catch (const pl::UsageError& e) {
    return report(e.what(), pl::kExitUsage);
  } catch (const pl::Error& e) {
    return report(e.what(), pl::kExitFailure);
  } catch (const std::bad_alloc&) {
    return report("out of memory", pl::kExitFailure);
  } catch (const std::exception& e) {
    return report(std::string("internal error: ") + e.what(), pl::kExitFailure);
  } catch (...) {
    return report("internal error: unknown exception", pl::kExitFailure);
  }
  return pl::kExitSuccess;
}
