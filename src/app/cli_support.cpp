// The command-line conventions (see cli_support.h).
#include "app/cli_support.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>
#include <numeric>
#include <regex>
#include <sstream>
#include <utility>

#include "core/error.h"

namespace pl::cli {

std::string HelpFormatter::make_option_name(const CLI::Option* option, bool isPositional) const {
  if (isPositional) return option->get_name(true, false);
  // CLI11 appends "{false}" to a negatable flag's name ("!--no-x"); list the plain names.
  std::vector<std::string> names;
  for (const std::string& name : option->get_snames()) names.push_back("-" + name);
  for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  return CLI::detail::join(names);
}

HelpFormatter::HelpFormatter() {
  label("Subcommands", "Commands");
  label("SUBCOMMAND", "COMMAND");
  label("SUBCOMMANDS", "COMMANDS");
  label("Positionals", "Arguments");
}

namespace {

/// CLI11's type name of an option's value, "BASE" followed by ":CHECK" for each check with a
/// description, as ("TYPE", "constraint"): ("INT", "in [1, 4096]"), ("{a,b}", ""), ("FLOAT", "> 0").
std::pair<std::string, std::string> typeAndConstraint(const std::string& typeName) {
  std::vector<std::string> parts;
  std::stringstream stream(typeName);
  for (std::string part; std::getline(stream, part, ':');) parts.push_back(part);
  if (parts.empty()) return {};
  std::string type = parts.front(), constraint;
  static const std::regex range(R"(^\S+ in \[(.+) - (.+)\]$)");
  for (size_t i = 1; i < parts.size(); ++i) {
    const std::string& check = parts[i];
    std::smatch match;
    std::string text;
    if (!check.empty() && check.front() == '{')
      type = check;  // the choices say what the value is
    else if (std::regex_match(check, match, range))
      text = "in [" + match[1].str() + ", " + match[2].str() + "]";
    else if (check == "POSITIVE")
      text = "> 0";
    else if (check == "NONNEGATIVE")
      text = ">= 0";
    else if (check == "FILE" || check == "DIR" || check == "PATH(existing)" || check == "PATH(non-existing)")
      type = check;
    else
      text = check;
    if (!text.empty()) constraint += (constraint.empty() ? "" : ", ") + text;
  }
  return {type, constraint};
}

}  // namespace

std::string HelpFormatter::make_option_opts(const CLI::Option* option) const {
  if (!option->get_option_text().empty()) return " " + option->get_option_text();
  std::string out;
  if (option->get_type_size() != 0) {
    const auto [type, constraint] = typeAndConstraint(option->get_type_name());
    if (!type.empty()) out += " " + get_label(type);
    if (!option->get_default_str().empty()) out += "=" + option->get_default_str();
    if (!constraint.empty()) out += " " + constraint;
    if (option->get_expected_max() == CLI::detail::expected_max_vector_size)
      out += " ...";
    else if (option->get_expected_min() > 1)
      out += " x " + std::to_string(option->get_expected());
    if (option->get_required()) out += " " + get_label("REQUIRED");
  }
  if (!option->get_envname().empty()) out += " (" + get_label("Env") + ":" + option->get_envname() + ")";
  if (!option->get_needs().empty()) {
    out += " " + get_label("Needs") + ":";
    for (const CLI::Option* other : option->get_needs()) out += " " + other->get_name();
  }
  if (!option->get_excludes().empty()) {
    out += " " + get_label("Excludes") + ":";
    for (const CLI::Option* other : option->get_excludes()) out += " " + other->get_name();
  }
  return out;
}

void groupCommands(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_group() == "Subcommands") sub->group("Commands");
    groupCommands(*sub);
  }
}

int editDistance(const std::string& a, const std::string& b) {
  // Optimal string alignment distance (Damerau–Levenshtein without repeated edits of one substring).
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<int>> d(n + 1, std::vector<int>(m + 1));
  for (size_t i = 0; i <= n; ++i) d[i][0] = int(i);
  for (size_t j = 0; j <= m; ++j) d[0][j] = int(j);
  for (size_t i = 1; i <= n; ++i)
    for (size_t j = 1; j <= m; ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

namespace {

/// "spp" for "--spp": a name without its leading dashes.
std::string withoutDashes(const std::string& name) {
  const size_t start = name.find_first_not_of('-');
  return start == std::string::npos ? std::string() : name.substr(start);
}

}  // namespace

std::optional<std::string> nearest(const std::string& typed, const std::vector<std::string>& candidates) {
  // Near enough: a third of the typed length in edits (at least 1, at most 3), or the one
  // candidate the typed text starts; nothing for a single letter.
  const std::string word = withoutDashes(typed);
  if (word.size() < 2) return std::nullopt;  // one letter: any guess is a guess
  const int allowed = std::clamp(int(word.size()) / 3, 1, 3);
  std::optional<std::string> best;
  int bestDistance = allowed + 1;
  std::vector<std::string> prefixed;
  for (const std::string& candidate : candidates) {
    const std::string name = withoutDashes(candidate);
    if (name.size() > word.size() && name.compare(0, word.size(), word) == 0)
      prefixed.push_back(candidate);
    const int distance = editDistance(word, name);
    if (distance < bestDistance) {
      bestDistance = distance;
      best = candidate;
    }
  }
  if (best) return best;
  if (prefixed.size() == 1) return prefixed.front();
  return std::nullopt;
}

std::vector<const CLI::Option*> acceptedOptions(const CLI::App& command) {
  std::vector<const CLI::Option*> options;
  for (const CLI::App* app = &command; app != nullptr; app = app->get_parent()) {
    for (const CLI::Option* option : app->get_options())
      if (!option->get_group().empty() && option->nonpositional()) options.push_back(option);
    if (!app->get_fallthrough()) break;
  }
  return options;
}

std::vector<const CLI::App*> visibleSubcommands(const CLI::App& command) {
  std::vector<const CLI::App*> subs;
  for (const CLI::App* sub : const_cast<CLI::App&>(command).get_subcommands([](CLI::App*) { return true; }))
    if (!sub->get_group().empty()) subs.push_back(sub);
  return subs;
}

namespace {

/// The deepest command selected on the command line (the app itself when none was).
const CLI::App* selectedLeaf(const CLI::App& app) {
  const CLI::App* current = &app;
  while (!current->get_subcommands().empty()) current = current->get_subcommands().front();
  return current;
}

/// "-o", "--output": every name of an option, with its dashes.
std::vector<std::string> optionNames(const CLI::Option* option) {
  std::vector<std::string> names;
  for (const std::string& name : option->get_snames()) names.push_back("-" + name);
  for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  return names;
}

}  // namespace

std::optional<std::string> unknownArgumentMessage(const CLI::App& app) {
  // What CLI11 could not place is left in remaining(), whatever error it then raised.
  const std::vector<std::string> left = app.remaining(true);
  if (left.empty()) return std::nullopt;
  const std::string& typed = left.front();
  const CLI::App* command = selectedLeaf(app);
  if (typed.size() > 1 && typed[0] == '-') {
    const std::string name = typed.substr(0, typed.rfind("--", 0) == 0 ? typed.find('=') : 2);
    std::vector<std::string> candidates;
    for (const CLI::Option* option : acceptedOptions(*command))
      for (const std::string& n : optionNames(option)) candidates.push_back(n);
    const std::optional<std::string> match = nearest(name, candidates);
    return fmt::format("unknown option '{}'{}", name, match ? fmt::format("; did you mean '{}'?", *match) : "");
  }
  const std::vector<const CLI::App*> subs = visibleSubcommands(*command);
  if (subs.empty()) return std::nullopt;  // an extra argument: CLI11's message says it
  std::vector<std::string> candidates;
  for (const CLI::App* sub : subs) candidates.push_back(sub->get_name());
  const std::optional<std::string> match = nearest(typed, candidates);
  return fmt::format("unknown command '{}'{}", typed, match ? fmt::format("; did you mean '{}'?", *match) : "");
}

std::string parseErrorMessage(const std::string& message) {
  static const std::regex missingOne(R"(^(\S+): 1 required (\S+(?: .*)?) missing$)");
  static const std::regex missingMany(R"(^(\S+): (\d+) required (\S+(?: .*)?) missing$)");
  static const std::regex tooFew(R"(^(\S+): At least (\d+) required but received (\d+)$)");
  static const std::regex unexpected(R"(^The following arguments? (?:was|were) not expected: (.*)$)");
  const auto typeText = [](const std::string& typeName) {
    const auto [type, constraint] = typeAndConstraint(typeName);
    return constraint.empty() ? type : type + " " + constraint;
  };
  std::smatch m;
  if (std::regex_match(message, m, missingOne)) return m[1].str() + ": missing its value (" + typeText(m[2]) + ")";
  if (std::regex_match(message, m, missingMany))
    return m[1].str() + ": missing its " + m[2].str() + " values (" + typeText(m[3]) + ")";
  if (std::regex_match(message, m, tooFew))
    return m[1].str() + ": expected " + m[2].str() + " values, got " + m[3].str();
  if (std::regex_match(message, m, unexpected)) {
    const std::string words = m[1];
    return words.find(' ') == std::string::npos ? "unexpected argument '" + words + "'" : "unexpected arguments: " + words;
  }
  return message;
}

std::optional<std::string> missingCommandMessage(const CLI::App& app, const CLI::ParseError& error) {
  if (dynamic_cast<const CLI::RequiredError*>(&error) == nullptr ||
      std::string(error.what()).find("ubcommand") == std::string::npos)
    return std::nullopt;
  const CLI::App* command = selectedLeaf(app);
  const std::vector<const CLI::App*> subs = visibleSubcommands(*command);
  if (command->get_require_subcommand_min() == 0 || subs.empty()) return std::nullopt;
  std::string names;
  for (size_t i = 0; i < subs.size(); ++i)
    names += (i == 0 ? "" : i + 1 == subs.size() ? " or " : ", ") + subs[i]->get_name();
  return "a command is required: " + names;
}

const CLI::App* commandListRequested(const CLI::App& app, const std::vector<std::string>& args) {
  const CLI::App* current = &app;
  for (const std::string& arg : args) {
    const CLI::App* next = nullptr;
    for (const CLI::App* sub : visibleSubcommands(*current))
      if (sub->check_name(arg)) next = sub;
    if (next == nullptr) return nullptr;
    current = next;
  }
  return current->get_require_subcommand_min() > 0 ? current : nullptr;
}

// --- bash completion ---------------------------------------------------------------------------

namespace {

std::string joined(const std::vector<std::string>& words) {
  return std::accumulate(words.begin(), words.end(), std::string(),
                         [](const std::string& a, const std::string& b) { return a.empty() ? b : a + " " + b; });
}

/// The fixed choices of an option checked with CLI::IsMember, whose type name then reads
/// "TEXT:{a,b,c}"; empty for any other option.
std::vector<std::string> choicesOf(const CLI::Option* option) {
  const std::string type = option->get_type_name();
  const size_t open = type.find(":{"), close = type.rfind('}');
  if (open == std::string::npos || close == std::string::npos || close < open) return {};
  std::vector<std::string> choices;
  std::stringstream list(type.substr(open + 2, close - open - 2));
  for (std::string choice; std::getline(list, choice, ',');)
    if (!choice.empty()) choices.push_back(choice);
  return choices;
}

/// Whether an option takes a value (a flag takes none).
bool takesValue(const CLI::Option* option) { return option->get_items_expected_max() > 0; }

/// Whether an option's value is a file or directory name: text that is not a fixed choice and
/// whose description speaks of one (a file type, "file", "image", "directory", "JSON", an
/// output), so that --eye X,Y,Z or --fstop N are not offered file names.
bool takesFile(const CLI::Option* option) {
  static const std::regex fileWords(
      R"(\.(plf|plv|exr|hdr|pfm|png|json|obj|gltf|glb|mp4)\b|\b(file|image|directory|JSON|PNG|path)\b|^Output|^Write|^Where)",
      std::regex::icase);
  return takesValue(option) && option->get_type_name().rfind("TEXT", 0) == 0 && choicesOf(option).empty() &&
         std::regex_search(option->get_description(), fileWords);
}

void addCompletionCases(const CLI::App& command, const std::string& path, std::string& specCases,
                        std::string& choiceCases) {
  std::vector<std::string> subs, opts, valued, files;
  for (const CLI::App* sub : visibleSubcommands(command)) subs.push_back(sub->get_name());
  for (const CLI::Option* option : acceptedOptions(command)) {
    std::vector<std::string> names = optionNames(option);
    // (-h/--help belongs to every command: listed once)
    names.erase(std::remove_if(names.begin(), names.end(),
                               [&](const std::string& n) { return std::find(opts.begin(), opts.end(), n) != opts.end(); }),
                names.end());
    opts.insert(opts.end(), names.begin(), names.end());
    if (!takesValue(option)) continue;
    valued.insert(valued.end(), names.begin(), names.end());
    if (takesFile(option)) files.insert(files.end(), names.begin(), names.end());
    const std::vector<std::string> choices = choicesOf(option);
    if (!choices.empty())
      for (const std::string& name : names)
        choiceCases += fmt::format("    \"{}|{}\") choices=\"{}\" ;;\n", path, name, joined(choices));
  }
  specCases += fmt::format("    \"{}\")\n      subs=\"{}\"\n      opts=\"{}\"\n      valued=\"{}\"\n      files=\"{}\" ;;\n",
                           path, joined(subs), joined(opts), joined(valued), joined(files));
  for (const CLI::App* sub : visibleSubcommands(command))
    addCompletionCases(*sub, path.empty() ? sub->get_name() : path + " " + sub->get_name(), specCases, choiceCases);
}

}  // namespace

std::string bashCompletion(const CLI::App& app) {
  std::string specCases, choiceCases;
  addCompletionCases(app, "", specCases, choiceCases);
  const std::string name = app.get_name();
  return fmt::format(
      R"(# bash completion for {0}; generated from its command-line definition by
# `{0} completion bash` (regenerate it rather than editing it).

# Sets, for the command path $1 ("" or e.g. "env convert"): subs (its commands), opts (its
# flags), valued (the flags that take a value) and files (those whose value is a file name).
__{0}_spec() {{
  subs="" opts="" valued="" files=""
  case "$1" in
{1}  esac
}}

# Sets choices: the values flag $2 of command path $1 accepts, when they are a fixed set.
__{0}_choices() {{
  choices=""
  case "$1|$2" in
{2}  esac
}}

_{0}() {{
  local cur prev cword i w path="" subs opts valued files choices
  local -a words
  if declare -F _init_completion >/dev/null 2>&1; then
    local split
    _init_completion -s || return  # -s: --flag=value completes the value
  else
    words=("${{COMP_WORDS[@]}}")
    cword=$COMP_CWORD
    cur=${{COMP_WORDS[COMP_CWORD]}}
    prev=${{COMP_WORDS[COMP_CWORD-1]}}
  fi
  __{0}_spec ""
  for ((i = 1; i < cword; i++)); do
    w=${{words[i]}}
    if [[ " $valued " == *" $w "* ]]; then
      i=$((i + 1))
    elif [[ $w != -* && " $subs " == *" $w "* ]]; then
      path=${{path:+$path }}$w
      __{0}_spec "$path"
    fi
  done
  if ((cword > 1)) && [[ " $valued " == *" $prev "* ]]; then
    __{0}_choices "$path" "$prev"
    if [[ -n $choices ]]; then
      mapfile -t COMPREPLY < <(compgen -W "$choices" -- "$cur")
    elif [[ " $files " == *" $prev "* ]]; then
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -f -- "$cur")
    fi
    return 0
  fi
  if [[ $cur == -* ]]; then
    mapfile -t COMPREPLY < <(compgen -W "$opts" -- "$cur")
  elif [[ -n $subs ]]; then
    mapfile -t COMPREPLY < <(compgen -W "$subs" -- "$cur")
  else
    compopt -o filenames 2>/dev/null
    mapfile -t COMPREPLY < <(compgen -f -- "$cur")
  fi
  return 0
}}
complete -F _{0} {0}
)",
      name, specCases, choiceCases);
}

// --- man page --------------------------------------------------------------------------------

namespace {

/// Text made safe for roff: backslashes escaped, no line starting with a control character,
/// characters beyond ASCII as groff's \[uXXXX] (so that no input encoding need be guessed).
std::string roffText(const std::string& text) {
  std::string out;
  bool lineStart = true;
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (lineStart && (c == '.' || c == '\'')) out += "\\&";
    lineStart = c == '\n';
    if (c == '\\') {
      out += "\\e";
    } else if (c < 0x80) {
      out += char(c);
    } else {
      // One UTF-8 sequence: its lead byte says how many continuation bytes follow.
      const int extra = c >= 0xF0 ? 3 : c >= 0xE0 ? 2 : c >= 0xC0 ? 1 : 0;
      uint32_t code = extra == 3 ? c & 0x07 : extra == 2 ? c & 0x0F : c & 0x1F;
      int taken = 0;
      for (; taken < extra && i + 1 < text.size() && (static_cast<unsigned char>(text[i + 1]) & 0xC0) == 0x80; ++taken)
        code = (code << 6) | (static_cast<unsigned char>(text[++i]) & 0x3F);
      out += extra == 0 || taken < extra ? std::string("?") : fmt::format("\\[u{:04X}]", code);
    }
  }
  return out;
}

/// An option or command name in roff: minus signs rather than hyphens (copyable from the page).
std::string roffName(const std::string& text) {
  std::string out;
  for (const char c : roffText(text)) out += c == '-' ? std::string("\\-") : std::string(1, c);
  return out;
}

std::string trim(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  size_t start = text.find_first_not_of(' ');
  return start == std::string::npos ? std::string() : text.substr(start);
}

/// One .TP entry per option, as --help shows it: the names and value in bold and italics,
/// the description below.
std::string roffOptions(const CLI::Formatter& formatter, const std::vector<const CLI::Option*>& options, bool positional) {
  std::string out;
  for (const CLI::Option* option : options) {
    const std::string opts = trim(formatter.make_option_opts(option));
    out += ".TP\n\\fB" + roffName(formatter.make_option_name(option, positional)) + "\\fR";
    if (!opts.empty()) out += " \\fI" + roffText(opts) + "\\fR";
    out += "\n" + roffText(trim(formatter.make_option_desc(option))) + "\n";
  }
  return out;
}

void roffCommand(const CLI::App& command, const std::string& path, const CLI::Formatter& formatter, std::string& out) {
  out += fmt::format(".SS \"{}\"\n{}\n", roffText(path), roffText(command.get_description()));
  std::string usage = trim(formatter.make_usage(&command, path));
  if (usage.rfind("Usage: ", 0) == 0) usage = usage.substr(7);
  out += ".PP\n.nf\n" + roffText(usage) + "\n.fi\n";
  std::vector<const CLI::Option*> positionals, options;
  for (const CLI::Option* option : command.get_options())
    if (!option->get_group().empty()) (option->nonpositional() ? options : positionals).push_back(option);
  if (!positionals.empty()) out += ".PP\nArguments:\n" + roffOptions(formatter, positionals, true);
  // --help is everywhere; the global options are listed once under GLOBAL OPTIONS.
  options.erase(std::remove_if(options.begin(), options.end(),
                               [&](const CLI::Option* o) { return o == command.get_help_ptr(); }),
                options.end());
  if (!options.empty()) out += ".PP\nOptions:\n" + roffOptions(formatter, options, false);
  for (const CLI::App* sub : visibleSubcommands(command)) roffCommand(*sub, path + " " + sub->get_name(), formatter, out);
}

std::string capitalised(std::string text) {
  if (!text.empty()) text[0] = char(std::toupper(static_cast<unsigned char>(text[0])));
  return text;
}

}  // namespace

std::string manPage(const CLI::App& app, const std::string& version) {
  const std::shared_ptr<CLI::FormatterBase> base = app.get_formatter();
  const HelpFormatter fallback;
  const auto* shared = dynamic_cast<const CLI::Formatter*>(base.get());
  const CLI::Formatter& formatter = shared ? *shared : fallback;
  const std::string name = app.get_name();
  std::string summary = app.get_description();
  if (summary.rfind(name + ": ", 0) == 0) summary = summary.substr(name.size() + 2);

  std::string out = fmt::format(
      ".\\\" Generated from the command-line definition by `{0} manpage`; regenerate it rather than editing it.\n"
      ".TH {1} 1 \"\" \"{0} {2}\" \"User Commands\"\n"
      ".SH NAME\n{0} \\- {3}\n"
      ".SH SYNOPSIS\n"
      "\\fB{0}\\fR [\\fIglobal-options\\fR] \\fIcommand\\fR [\\fIoptions\\fR] [\\fIarguments\\fR]\n.br\n"
      "\\fB{0}\\fR [\\fIcommand\\fR] \\fB\\-\\-help\\fR\n.br\n"
      "\\fB{0} \\-\\-version\\fR\n"
      ".SH DESCRIPTION\n{4}.\n.PP\n"
      "Run without arguments, {0} lists its commands. Every command shows its options with \\fB\\-\\-help\\fR. "
      "The global options may come before or after the command name. An option marked REQUIRED must be given.\n",
      name, [&] {
        std::string upper = name;
        std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return char(std::toupper(c)); });
        return upper;
      }(),
      roffText(version), roffText(summary), roffText(capitalised(summary)));

  std::vector<const CLI::Option*> global;
  for (const CLI::Option* option : app.get_options())
    if (!option->get_group().empty() && option->nonpositional()) global.push_back(option);
  out += ".SH GLOBAL OPTIONS\n" + roffOptions(formatter, global, false);

  out += ".SH COMMANDS\n";
  for (const CLI::App* sub : visibleSubcommands(app)) roffCommand(*sub, name + " " + sub->get_name(), formatter, out);

  out += fmt::format(
      ".SH EXIT STATUS\n"
      ".TP\n.B {}\nSuccess (also after \\fB\\-\\-help\\fR and \\fB\\-\\-version\\fR).\n"
      ".TP\n.B {}\nThe command ran into a problem: a bad input file, an output that cannot be written, not enough "
      "memory, an internal error.\n"
      ".TP\n.B {}\nThe command line is wrong: an unknown command or option, a missing or malformed value, a value out "
      "of range, a bad combination.\n"
      ".TP\n.B 129, 130, 143\nInterrupted by SIGHUP, SIGINT (Ctrl-C) or SIGTERM (128 + the signal number); the "
      "temporary files of unfinished outputs are removed.\n"
      ".PP\nEvery error is one line on standard error: \\fB{}: error:\\fR followed by what was wrong.\n",
      int(kExitSuccess), int(kExitFailure), int(kExitUsage), name);
  out += fmt::format(
      ".SH SEE ALSO\nThe README and the manual under share/doc/{0} of the installation prefix. Bash completion: "
      "\\fB{0} completion bash\\fR prints the script installed as share/bash-completion/completions/{0}.\n",
      name);
  return out;
}

// --- the hidden commands that print them -------------------------------------------------------

namespace {

void writeOrPrint(const std::string& text, const std::string& output) {
  if (output.empty()) {
    std::cout << text << std::flush;
    return;
  }
  std::ofstream file(output, std::ios::binary);
  file << text;
  file.close();
  if (!file) throw FileError(output, output + ": cannot write");
}

}  // namespace

void addGeneratorCommands(CLI::App& app, const std::string& version) {
  auto output = std::make_shared<std::string>();
  CLI::App* completion = app.add_subcommand("completion", "Print a shell completion script");
  completion->group("");  // hidden: a packaging step, not part of the pipeline
  completion->require_subcommand(1);
  CLI::App* bash = completion->add_subcommand("bash", "Bash completion (source it, or install it in "
                                                      "share/bash-completion/completions/plenoptic)");
  bash->add_option("-o,--output", *output, "Write it to FILE instead of standard output");
  bash->callback([&app, output] { writeOrPrint(bashCompletion(app), *output); });

  CLI::App* man = app.add_subcommand("manpage", "Print the man page (roff)");
  man->group("");
  man->add_option("-o,--output", *output, "Write it to FILE instead of standard output");
  man->callback([&app, output, version] { writeOrPrint(manPage(app, version), *output); });
}

}  // namespace pl::cli
