#pragma once
// The conventions every `plenoptic` command follows, kept out of the commands themselves:
// the help layout, suggestions for a mistyped command or flag, and the bash completion and
// man page, both generated from the CLI11 definition the program parses with (so they cannot
// drift from it).
#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace pl::cli {

/// CLI11's formatter without its artefacts: negatable flags ("!--no-x") are listed as
/// "--no-x", not "--no-x{false}"; a value's type and check read "INT=64 in [1, 4096]",
/// "{mis,nee,bsdf}=mis", "FLOAT > 0" rather than "INT:INT in [1 - 4096]=64",
/// "TEXT:{mis,nee,bsdf}=mis", "FLOAT:POSITIVE"; "Commands" and "Arguments" rather than
/// "Subcommands" and "Positionals". Set on the top-level app before any subcommand is added
/// (subcommands share their parent's formatter).
class HelpFormatter : public CLI::Formatter {
 public:
  HelpFormatter();
  std::string make_option_name(const CLI::Option* option, bool isPositional) const override;
  std::string make_option_opts(const CLI::Option* option) const override;
};

/// Lists the visible subcommands of `app`, however deep, under "Commands" rather than CLI11's
/// "Subcommands" (the group a subcommand is shown in is its own setting). Call once all are added.
void groupCommands(CLI::App& app);

/// "TEXT REQUIRED": the option text that marks an option required in the help when CLI11
/// cannot enforce it (required unless another flag is given; the command checks it itself).
/// Say the exception in the option's description.
inline constexpr const char* kRequiredText = "TEXT REQUIRED";

/// Levenshtein distance with adjacent transpositions counted as one edit ("tarce" → "trace").
int editDistance(const std::string& a, const std::string& b);

/// The candidate nearest to `typed`, when it is near enough to be a likely typo or an
/// unambiguous prefix; nothing otherwise.
std::optional<std::string> nearest(const std::string& typed, const std::vector<std::string>& candidates);

/// After a CLI11 parse error of `app`: "unknown command 'trac'; did you mean 'trace'?" or
/// "unknown option '--spq'; did you mean '--spp'?" for the first argument no command knew,
/// or nothing when the error is of another kind (missing value, out of range, ...).
std::optional<std::string> unknownArgumentMessage(const CLI::App& app);

/// After CLI11's parse error `error` of `app`: "a command is required: demo, trace, ... or
/// compress" when it is CLI11's "A subcommand is required" (the command selected last needs
/// a subcommand and none was given); nothing for any other error.
std::optional<std::string> missingCommandMessage(const CLI::App& app, const CLI::ParseError& error);

/// CLI11's parse-error text in the program's words: "--spp: missing its value (INT in
/// [1, 16777216])" rather than "--spp: 1 required INT:INT in [1 - 16777216] missing",
/// "unexpected argument 'b'" rather than "The following argument was not expected: b".
/// Any other text is returned as it is.
std::string parseErrorMessage(const std::string& message);

/// When `args` (argv without the program name) are only command names ending at a command
/// that needs a subcommand ("", "env"), that command: its help is what the user is after.
const CLI::App* commandListRequested(const CLI::App& app, const std::vector<std::string>& args);

/// The options a command accepts: its own, then those of the commands above it that it lets
/// through (CLI11's fallthrough, e.g. the global --threads after the command name).
std::vector<const CLI::Option*> acceptedOptions(const CLI::App& command);

/// The visible subcommands of `command` (hidden ones, such as `completion`, left out).
std::vector<const CLI::App*> visibleSubcommands(const CLI::App& command);

/// A bash completion script for `app`: commands, their flags, the values of flags with a
/// fixed set of choices, and file names for file arguments.
std::string bashCompletion(const CLI::App& app);

/// A man page (roff, man(7) macros) for `app`: synopsis, global options, every command with
/// its arguments and options as --help lists them, and the exit statuses.
std::string manPage(const CLI::App& app, const std::string& version);

/// Adds the hidden `completion bash` and `manpage` commands that print the two above (the
/// build writes them into share/, see cmake/install.cmake).
void addGeneratorCommands(CLI::App& app, const std::string& version);

}  // namespace pl::cli
