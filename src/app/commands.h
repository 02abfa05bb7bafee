#pragma once
// Subcommands of the `plenoptic` program. Each lives in its own cmd_<name>.cpp with its own
// options struct (ranges and defaults declared in one place) and registers itself on the
// CLI11 app; main.cpp only lists them.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <memory>

namespace pl {

/// Options every subcommand understands (given before or after the subcommand name).
struct GlobalOptions {
  int threads = 0;        ///< 0 = all hardware threads
  uint64_t seed = 0;      ///< base seed of every random stream
  bool quiet = false;     ///< no progress bars
};

/// Applies what the library jobs do not own: --quiet silences progress bars. (The jobs make
/// their own thread pool of --threads.)
void applyGlobalOptions(const GlobalOptions& global);

/// What every command's callback not built on a job (jobs/jobs.h) creates first: the thread pool (with FTZ/DAZ workers)
/// sized by --threads, and progress bars silenced by --quiet.
class Runtime {
 public:
  explicit Runtime(const GlobalOptions& global);
  ~Runtime();
  int threads() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

void addDemoCommand(CLI::App& app, const GlobalOptions& global);
void addTraceCommand(CLI::App& app, const GlobalOptions& global);
void addCompareCommand(CLI::App& app, const GlobalOptions& global);
void addTonemapCommand(CLI::App& app, const GlobalOptions& global);
void addBakeCommand(CLI::App& app, const GlobalOptions& global);
void addInfoCommand(CLI::App& app, const GlobalOptions& global);
void addRenderCommand(CLI::App& app, const GlobalOptions& global);
void addViewCommand(CLI::App& app, const GlobalOptions& global);
void addEnvCommand(CLI::App& app, const GlobalOptions& global);
void addCompressCommand(CLI::App& app, const GlobalOptions& global);

}  // namespace pl
