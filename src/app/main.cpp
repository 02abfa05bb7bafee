// plenoptic — physically based global illumination with precomputed light fields.
#include <fmt/format.h>

#include <cstdio>
#include <exception>

#include "app/commands.h"
#include "core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"plenoptic: physically based global illumination, precomputed as a light field over the "
               "scene's surfaces and rendered in real time"};
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand name
  app.set_version_flag("--version", "plenoptic 0.1.0");

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const pl::Error& e) {
    fmt::print(stderr, "plenoptic: error: {}\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "plenoptic: internal error: {}\n", e.what());
    return 2;
  }
  return 0;
}
