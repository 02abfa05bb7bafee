// Runs the `plenoptic` executable (PLENOPTIC_BINARY) for what every command shares: the one
// error form and its exit statuses (core/error.h), non-finite flag values, output checks
// before any work, the memory guard, non-regular input files, and Ctrl-C during a bake.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

class AppCli : public cli_test::CliTest {
 protected:
  /// The files the command left in the test's directory, besides the captured stdout and
  /// stderr and the inputs named in `inputs`.
  std::vector<std::string> outputs(const std::vector<std::string>& inputs = {}) const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      if (name != "stdout.txt" && name != "stderr.txt" && std::find(inputs.begin(), inputs.end(), name) == inputs.end())
        names.push_back(name);
    }
    return names;
  }
  /// Runs `ARGUMENTS --quiet` and expects exit status `status`, nothing on stdout and one
  /// line "plenoptic: error: ..." on stderr containing `expected`.
  void expectError(const std::string& arguments, int status, const std::string& expected) const {
    std::string out, err;
    EXPECT_EQ(run(arguments, &out, &err), status) << arguments << "\n" << err;
    EXPECT_EQ(out, "") << arguments;
    EXPECT_EQ(err.rfind("plenoptic: error: ", 0), 0u) << arguments << "\n" << err;
    EXPECT_NE(err.find(expected), std::string::npos) << arguments << "\n" << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << arguments << "\n" << err;
  }
  std::string q(const std::string& name) const { return "\"" + path(name) + "\""; }
};

TEST_F(AppCli, FlagErrorsExitWithStatus2InTheOneErrorForm) {
  const std::string trace = "trace cornell -o " + q("t.png") + " --width 8 --height 8 --spp 1";
  // (run adds --quiet: a global option alone is no command)
  expectError("", 2, "a command is required: demo, trace, bake, info, render, view, compare, tonemap, env or compress "
                     "(see 'plenoptic --help')");
  expectError("env --quiet", 2, "a command is required: convert, sh, irradiance, prefilter or splitsum-error");
  expectError("--threads 99999", 2, "--threads: Value 99999 not in range 0 to 4096");  // not "a command is required"
  expectError(trace + " --no-such-flag", 2, "--no-such-flag");
  expectError(trace + " --spp", 2, "--spp");
  // A flag's value missing at the end of the line (run() would add --quiet after it).
  for (const auto& [arguments, expected] :
       {std::pair<std::string, std::string>{trace + " --spp", "--spp: missing its value (INT in [1, 16777216]) "
                                                             "(see 'plenoptic trace --help')\n"},
        {trace + " --strategy", "--strategy: missing its value ({mis,nee,bsdf}) (see 'plenoptic trace --help')\n"}}) {
    std::string out, err;
    EXPECT_EQ(cli_test::runPlenoptic(arguments, dir_, &out, &err), 2) << arguments;
    EXPECT_EQ(err, "plenoptic: error: " + expected) << arguments;
  }
  expectError(trace + " --pixel 3", 2, "--pixel: expected 2 values, got 1");
  expectError("info a.plf b.plf", 2, "unexpected argument 'b.plf' (see 'plenoptic info --help')");
  expectError(trace + " --spp abc", 2, "--spp");
  expectError(trace + " --spp 0", 2, "--spp");
  expectError(trace + " --strategy fast", 2, "--strategy");
  expectError(trace + " --fstop 8", 2, "--fstop/--shutter/--iso");
  expectError("trace cornell --spp 1", 2, "an output image is required");
  expectError("render " + q("a.plf") + " -o " + q("f%03d.png"), 2, "needs a camera path");
  expectError("frobnicate", 2, "unknown command 'frobnicate' (see 'plenoptic --help')");
  expectError("demo --preset fast --output-dir " + q("demo"), 2, "--preset: fast not in {draft,default,high}");
  EXPECT_TRUE(outputs().empty());
}

TEST_F(AppCli, NonFiniteValuesOfEveryFloatFlagAreRefusedUpFront) {
  const std::string trace = "trace cornell -o " + q("t.exr") + " --width 8 --height 8 --spp 1";
  const std::string bake = "bake cornell -o " + q("b.plf") + " --preset draft";
  for (const std::string& flags :
       {trace + " --fov nan", trace + " --fov 1e39", trace + " --aperture nan", trace + " --exposure nan",
        trace + " --exposure inf", trace + " --focus-distance nan", trace + " --scene-unit inf",
        trace + " --key nan", trace + " --white inf", trace + " --eye nan,0,0", bake + " --tixels-across nan",
        bake + " --tolerance nan", bake + " --tolerance -inf", "compare " + q("a.exr") + " " + q("b.exr") + " --peak nan",
        "compare " + q("a.exr") + " " + q("b.exr") + " --max-relmse nan",
        "compare " + q("a.exr") + " " + q("b.exr") + " --heatmap-max inf"}) {
    std::string out, err;
    EXPECT_EQ(run(flags, &out, &err), 2) << flags << "\n" << err;
    EXPECT_EQ(err.rfind("plenoptic: error: ", 0), 0u) << flags << "\n" << err;
  }
  expectError(trace + " --fov nan", 2, "--fov: expected a finite number, got 'nan'");
  expectError(bake + " --tolerance nan", 2, "--tolerance: expected a finite number, got 'nan'");
  EXPECT_TRUE(outputs().empty());  // nothing traced or baked
}

TEST_F(AppCli, HelpAndVersionGoToStdoutWithStatus0) {
  for (const std::string flags : {"--help", "--version", "trace --help", "bake --help", "env convert --help"}) {
    std::string out, err;
    EXPECT_EQ(run(flags, &out, &err), 0) << flags << "\n" << err;
    EXPECT_FALSE(out.empty()) << flags;
    EXPECT_EQ(err, "") << flags;
  }
  // The CMake project version, then `git describe` of the checkout it was built from.
  std::string out;
  run("--version", &out);
  EXPECT_TRUE(std::regex_match(out, std::regex(R"(plenoptic \d+\.\d+\.\d+( \([A-Za-z0-9._+-]+\))?\n)"))) << out;
}

// --- Conventions of the command line (cli_support.h) ----------------------------------------------

/// Every command and command group, as typed after `plenoptic`.
const std::vector<std::string> kCommands = {
    "",        "demo",        "trace",  "bake",           "info",          "render",
    "view",    "compare",     "tonemap", "env",           "env convert",   "env sh",
    "env irradiance", "env prefilter", "env splitsum-error", "compress"};

TEST_F(AppCli, NoArgumentsPrintsTheCommandListWithStatus0) {
  std::string out, err;
  EXPECT_EQ(cli_test::runPlenoptic("", dir_, &out, &err), 0) << err;
  EXPECT_EQ(err, "");
  EXPECT_EQ(out.rfind("plenoptic: physically based global illumination", 0), 0u) << out;
  for (const char* command : {"demo", "trace", "bake", "info", "render", "view", "compare", "tonemap", "env", "compress"})
    EXPECT_TRUE(std::regex_search(out, std::regex(std::string("\n  ") + command + " +\\S"))) << command << "\n" << out;
  EXPECT_EQ(out.find("completion"), std::string::npos) << "hidden commands listed:\n" << out;
  EXPECT_EQ(out.find("manpage"), std::string::npos) << out;
  // A command group alone: its own list.
  EXPECT_EQ(cli_test::runPlenoptic("env", dir_, &out, &err), 0) << err;
  EXPECT_EQ(err, "");
  EXPECT_NE(out.find("Usage: plenoptic env [OPTIONS] COMMAND"), std::string::npos) << out;
  for (const char* command : {"convert", "sh", "irradiance", "prefilter", "splitsum-error"})
    EXPECT_NE(out.find(std::string("  ") + command + " "), std::string::npos) << command << "\n" << out;
}

TEST_F(AppCli, AnUnknownCommandOrFlagSuggestsTheNearest) {
  const std::string trace = "trace cornell -o " + q("t.png") + " --width 8 --height 8 --spp 1";
  expectError("trac", 2, "unknown command 'trac'; did you mean 'trace'? (see 'plenoptic --help')");
  expectError("tarce cornell", 2, "unknown command 'tarce'; did you mean 'trace'?");
  expectError("rendr a.plf", 2, "unknown command 'rendr'; did you mean 'render'?");
  expectError("env convrt x.exr", 2, "unknown command 'convrt'; did you mean 'convert'? (see 'plenoptic env --help')");
  expectError(trace + " --spq 4", 2, "unknown option '--spq'; did you mean '--spp'? (see 'plenoptic trace --help')");
  expectError(trace + " --widht=8", 2, "unknown option '--widht'; did you mean '--width'?");
  expectError("--treads 2 " + trace, 2, "unknown option '--treads'; did you mean '--threads'?");
  expectError(trace + " --thread 2", 2, "did you mean '--threads'?");  // a global option after the command
  expectError("bake cornell -o " + q("b.plf") + " --prest draft", 2, "did you mean '--preset'?");
  // Nothing near: no guess.
  expectError(trace + " --zzzzzz", 2, "unknown option '--zzzzzz' (see 'plenoptic trace --help')");
  expectError("xyzzy", 2, "unknown command 'xyzzy' (see 'plenoptic --help')");
  EXPECT_TRUE(outputs().empty());
}

/// The help line of option `name` ("-o,--output") in `help`, or "" when there is none.
std::string helpLine(const std::string& help, const std::string& name) {
  std::istringstream lines(help);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("  " + name + " ", 0) == 0) return line;
  return "";
}

TEST_F(AppCli, RequiredFlagsAreMarkedInTheHelp) {
  std::string out;
  ASSERT_EQ(run("trace --help", &out), 0);
  EXPECT_NE(helpLine(out, "-o,--output").find(" REQUIRED"), std::string::npos) << out;  // unless --pixel: says so
  EXPECT_NE(helpLine(out, "-o,--output").find("not needed with --pixel"), std::string::npos) << out;
  EXPECT_EQ(helpLine(out, "--spp").find("REQUIRED"), std::string::npos) << out;
  for (const char* command : {"bake", "render", "tonemap", "compress", "env convert"}) {
    ASSERT_EQ(run(std::string(command) + " --help", &out), 0) << command;
    EXPECT_NE(helpLine(out, "-o,--output").find(" REQUIRED"), std::string::npos) << command << "\n" << out;
  }
}

/// The commands a --help output lists under "Commands:".
std::vector<std::string> listedCommands(const std::string& help) {
  std::vector<std::string> names;
  const size_t at = help.find("\nCommands:\n");
  if (at == std::string::npos) return names;
  std::istringstream lines(help.substr(at + 11));
  for (std::string line; std::getline(lines, line) && line.rfind("  ", 0) == 0;)
    names.push_back(line.substr(2, line.find(' ', 2) - 2));
  return names;
}

TEST_F(AppCli, EveryHelpIsFreeOfFormattingArtefacts) {
  // kCommands holds every command the program lists (so a new one is checked here too).
  for (const std::string& command : kCommands) {
    std::string out;
    ASSERT_EQ(run(command + " --help", &out), 0) << command;
    for (const std::string& sub : listedCommands(out)) {
      const std::string full = command.empty() ? sub : command + " " + sub;
      EXPECT_NE(std::find(kCommands.begin(), kCommands.end(), full), kCommands.end()) << full << " is not in kCommands";
    }
  }
  EXPECT_EQ(listedCommands([&] { std::string out; run("--help", &out); return out; }()).size(), 10u);
  for (const std::string& command : kCommands) {
    std::string out, err;
    ASSERT_EQ(run(command + " --help", &out, &err), 0) << command << "\n" << err;
    EXPECT_EQ(err, "") << command;
    EXPECT_EQ(out.find("{false}"), std::string::npos) << command << "\n" << out;
    EXPECT_EQ(out.find("{true}"), std::string::npos) << command << "\n" << out;
    // The program's name, not the path it was run by.
    EXPECT_NE(out.find("Usage: plenoptic" + (command.empty() ? "" : " " + command) + " "), std::string::npos)
        << command << "\n" << out;
    EXPECT_EQ(out.find(PLENOPTIC_BINARY), std::string::npos) << command << "\n" << out;
  }
  std::string out;
  ASSERT_EQ(run("demo --help", &out), 0);
  EXPECT_NE(helpLine(out, "--no-walkthrough"), "") << out;
  // A value's type and its check, each once: not "INT:INT in [1 - 16384]=640".
  ASSERT_EQ(run("trace --help", &out), 0);
  EXPECT_EQ(out.find("INT:INT"), std::string::npos) << out;
  EXPECT_EQ(out.find("FLOAT:"), std::string::npos) << out;
  EXPECT_EQ(out.find("TEXT:{"), std::string::npos) << out;
  EXPECT_EQ(helpLine(out, "--width").rfind("  --width INT=640 in [1, 16384]", 0), 0u) << out;
  EXPECT_EQ(helpLine(out, "--strategy").rfind("  --strategy {mis,nee,bsdf}=mis", 0), 0u) << out;
  EXPECT_EQ(helpLine(out, "--scene-unit").rfind("  --scene-unit FLOAT > 0", 0), 0u) << out;
  EXPECT_NE(out.find("\nArguments:\n  scene TEXT REQUIRED "), std::string::npos) << out;
}

/// What the bash completion proposes for `words` (the last one being completed, "" for a new
/// word) with `script` (what `plenoptic completion bash` prints), after running `setup` (e.g.
/// sourcing the bash-completion package, whose _init_completion the script then uses).
std::string complete(const std::string& script, const std::vector<std::string>& words, const std::string& setup = "") {
  std::string array;
  for (const std::string& word : words) array += " '" + word + "'";
  const std::string command = "bash --norc --noprofile -c '" + setup +
                              " source \"$0\" && COMP_WORDS=(\"$@\") && COMP_CWORD=$((${#COMP_WORDS[@]} - 1)) && "
                              "COMP_LINE=\"$*\" && COMP_POINT=${#COMP_LINE} && _plenoptic && echo \"${COMPREPLY[*]}\"' " +
                              script + array;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return "(popen failed)";
  std::string out;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  ::pclose(pipe);
  if (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

TEST_F(AppCli, BashCompletionComesFromTheCommandLineDefinition) {
  std::string out, err;
  ASSERT_EQ(run("completion bash", &out, &err), 0) << err;
  EXPECT_NE(out.find("complete -F _plenoptic plenoptic"), std::string::npos);
  EXPECT_NE(out.find("subs=\"demo trace bake info render view compare tonemap env compress\""), std::string::npos) << out;
  ASSERT_EQ(run("completion bash -o " + q("plenoptic.bash"), &out, &err), 0) << err;
  const std::string script = path("plenoptic.bash");
  std::ofstream(path("scene.obj")) << "";
  // Plain bash, and bash with the bash-completion package loaded when it is installed.
  std::vector<std::string> setups = {""};
  if (fs::exists("/usr/share/bash-completion/bash_completion"))
    setups.push_back("source /usr/share/bash-completion/bash_completion &&");
  for (const std::string& setup : setups) {
    SCOPED_TRACE(setup.empty() ? "plain bash" : "with bash-completion");
    EXPECT_EQ(complete(script, {"plenoptic", "tr"}, setup), "trace");
    EXPECT_EQ(complete(script, {"plenoptic", "--threads", "4", "b"}, setup), "bake");
    EXPECT_EQ(complete(script, {"plenoptic", "trace", "cornell", "--sp"}, setup), "--spp");
    EXPECT_EQ(complete(script, {"plenoptic", "trace", "--strategy", ""}, setup), "mis nee bsdf");
    EXPECT_EQ(complete(script, {"plenoptic", "env", "c"}, setup), "convert");
    EXPECT_EQ(complete(script, {"plenoptic", "env", "prefilter", "--mo"}, setup), "--model");
    EXPECT_EQ(complete(script, {"plenoptic", "demo", "--no-w"}, setup), "--no-walkthrough");
    EXPECT_EQ(complete(script, {"plenoptic", "bake", "--thr"}, setup), "--threads");  // global flags after the command
    // File arguments complete file names.
    EXPECT_EQ(complete(script, {"plenoptic", "trace", path("scene.o")}, setup), path("scene.obj"));
    EXPECT_EQ(complete(script, {"plenoptic", "trace", "cornell", "-o", path("scene.o")}, setup), path("scene.obj"));
    EXPECT_EQ(complete(script, {"plenoptic", "bake", "cornell", "--stats", path("scene.o")}, setup), path("scene.obj"));
    // Values that are no file names: nothing offered.
    EXPECT_EQ(complete(script, {"plenoptic", "trace", "cornell", "--eye", path("scene.o")}, setup), "");
    EXPECT_EQ(complete(script, {"plenoptic", "trace", "cornell", "--spp", ""}, setup), "");
  }
}

TEST_F(AppCli, ManPageComesFromTheCommandLineDefinition) {
  std::string out, err;
  ASSERT_EQ(run("manpage", &out, &err), 0) << err;
  EXPECT_NE(out.find("\n.TH PLENOPTIC 1 "), std::string::npos) << out;
  EXPECT_NE(out.find(".SH NAME\nplenoptic \\- physically based global illumination"), std::string::npos) << out;
  for (const std::string& command : kCommands)
    if (!command.empty()) {
      EXPECT_NE(out.find(".SS \"plenoptic " + command + "\""), std::string::npos) << command;
    }
  EXPECT_NE(out.find("\\fB\\-\\-spp\\fR"), std::string::npos);
  EXPECT_NE(out.find("\\fB\\-\\-no\\-walkthrough\\fR\n"), std::string::npos);
  EXPECT_EQ(out.find("{false}"), std::string::npos);
  EXPECT_NE(out.find(".SH EXIT STATUS"), std::string::npos);
}

TEST_F(AppCli, ProblemsFoundByACommandExitWithStatus1) {
  expectError("trace " + q("missing.obj") + " -o " + q("t.png"), 1, "missing.obj");
  expectError("info " + q("missing.plf"), 1, "missing.plf");
  EXPECT_TRUE(outputs().empty());
}

TEST_F(AppCli, OutputsAreCheckedBeforeAnyWork) {
  const std::string bake = "bake cornell --preset draft --tixels-across 8 --directions 16";
  // Wrong extensions are usage errors.
  expectError(bake + " -o " + q("out.exr"), 2, "-o " + path("out.exr") + ": expected a .plf file name, not '.exr'");
  expectError(bake + " -o " + q("b.plf") + " --visibility " + q("b.bin"), 2, "--visibility");
  expectError("trace cornell --spp 1 -o " + q("t.exr") + " --variance " + q("v.png"), 2, "--variance");
  expectError("render " + q("a.plf") + " -o " + q("a.tiff"), 2, "expected a .exr, .hdr, .pfm or .png file name");
  // Two outputs that are one file (however spelt).
  fs::create_directory(path("sub"));
  expectError(bake + " -o " + q("b.plf") + " --stats " + q("sub/../b.plf"), 2, "are the same file");
  expectError("trace cornell --spp 1 -o " + q("t.exr") + " --variance " + q("t.exr"), 2, "are the same file");
  // A directory where the file should go: nothing is written beside it (no renders.plv).
  fs::create_directory(path("renders.plf"));
  expectError(bake + " -o " + q("renders.plf"), 1, path("renders.plf") + ": is a directory");
  // --stats into a missing directory: refused before the bake writes its .plf and .plv.
  expectError(bake + " -o " + q("b.plf") + " --stats " + q("missing/s.json"), 1,
              "--stats " + path("missing/s.json") + ": directory '" + path("missing") + "' does not exist");
  expectError("trace cornell --spp 1 --width 8 --height 8 -o " + q("t.exr") + " --stats " + q("missing/s.json"), 1,
              "does not exist");
  std::ofstream(path("file.exr")) << "x";
  expectError("trace cornell --spp 1 -o " + q("file.exr/t.exr"), 1, "'" + path("file.exr") + "' is not a directory");
  EXPECT_EQ(outputs({"file.exr", "sub"}), std::vector<std::string>{"renders.plf"});
  EXPECT_TRUE(fs::is_empty(path("renders.plf")));
}

TEST_F(AppCli, NonRegularInputFilesAreRefusedWithoutHanging) {
  // Opening a FIFO for reading blocks until a writer comes; `timeout` turns a hang into a
  // failure (status 124) instead of a stuck test.
  ASSERT_EQ(::mkfifo(path("fifo.plf").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(path("fifo.obj").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(path("fifo.exr").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(path("fifo.json").c_str(), 0600), 0);
  struct Case {
    std::string arguments, file;
  };
  for (const Case& c : {Case{"info " + q("fifo.plf"), "fifo.plf"}, Case{"render " + q("fifo.plf") + " -o " + q("r.exr"), "fifo.plf"},
                        Case{"trace " + q("fifo.obj") + " -o " + q("t.exr"), "fifo.obj"},
                        Case{"bake " + q("fifo.obj") + " -o " + q("b.plf"), "fifo.obj"},
                        Case{"tonemap " + q("fifo.exr") + " -o " + q("t.png"), "fifo.exr"},
                        Case{"compare " + q("fifo.exr") + " " + q("fifo.exr"), "fifo.exr"},
                        Case{"trace " + q("fifo.json") + " -o " + q("t.exr"), "fifo.json"}}) {
    std::string out, err;
    const int status =
        cli_test::runPlenoptic(c.arguments + " --quiet", dir_, &out, &err, "timeout 60");
    EXPECT_EQ(status, 1) << c.arguments << "\n" << err;
    EXPECT_NE(err.find("plenoptic: error: " + path(c.file) + ": not a regular file (a FIFO)"), std::string::npos)
        << c.arguments << "\n" << err;
  }
  expectError("info " + q("."), 1, "not a regular file (a directory)");
  expectError("info /dev/zero", 1, "/dev/zero: not a regular file (a character device)");
}

TEST_F(AppCli, MemoryGuardRefusesWhatWouldNotFitWithTheEstimateAndTheFlag) {
  // `ulimit -v` (address space) lowers the memory the guard counts as available, so the
  // refusal does not depend on the machine's memory: 2 GiB here, while a 16384² trace needs
  // two float RGB images and the buffers of writing one (about 12 GiB).
  const std::string limit = "ulimit -v 2097152;";
  std::string out, err;
  EXPECT_EQ(cli_test::runPlenoptic("trace cornell -o " + q("t.exr") + " --width 16384 --height 16384 --quiet", dir_,
                                   &out, &err, limit),
            1)
      << err;
  EXPECT_NE(err.find("plenoptic: error: trace at 16384x16384: estimated memory 12.00 GiB exceeds the "),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("lower --width/--height"), std::string::npos) << err;
  // The bake: 65536 gather directions per tixel make a visibility field of many GiB, refused
  // when it must be held (left to itself the bake streams it from the .plv: bake_cli_test).
  EXPECT_EQ(cli_test::runPlenoptic("bake cornell -o " + q("b.plf") + " --directions 65536 --visibility-memory held --quiet",
                                   dir_, &out, &err, limit),
            1)
      << err;
  EXPECT_NE(err.find("bake (visibility field and light-field values): estimated memory "), std::string::npos)
      << err;
  EXPECT_NE(err.find("lower --preset, --tixels-across or --directions, or let the visibility field stream from its "
                     ".plv (--visibility-memory auto)"),
            std::string::npos)
      << err;
  // Render: a small light field, a frame too large for the limit.
  ASSERT_EQ(run("bake cornell -o " + q("small.plf") + " --preset draft --tixels-across 8 --directions 16", &out, &err), 0)
      << err;
  EXPECT_EQ(cli_test::runPlenoptic("render " + q("small.plf") + " -o " + q("r.exr") +
                                       " --width 16384 --height 16384 --quiet",
                                   dir_, &out, &err, limit),
            1)
      << err;
  EXPECT_NE(err.find("render at 16384x16384: estimated memory 9.00 GiB exceeds the "), std::string::npos)
      << err;
  std::vector<std::string> written = outputs();
  std::sort(written.begin(), written.end());
  EXPECT_EQ(written, (std::vector<std::string>{"small.plf", "small.pls", "small.plt", "small.plv"}));
}

TEST_F(AppCli, InterruptedBakeRemovesItsTemporaryFilesAndSaysSo) {
  // A high-preset bake writes a visibility field of about 270 MB through a hidden temporary
  // file; SIGINT arrives while that temporary exists (polled every millisecond).
  const std::string errFile = path("bake_stderr.txt");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int fd = ::open(errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, STDERR_FILENO);
    ::execl(PLENOPTIC_BINARY, PLENOPTIC_BINARY, "bake", "cornell", "--preset", "high", "-o",
            path("c.plf").c_str(), "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  auto temporaries = [&] {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind(".", 0) == 0 && name.find(".tmp-") != std::string::npos) names.push_back(name);
    }
    return names;
  };
  bool seen = false;
  int status = 0;
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::minutes(5)) {
    if (!temporaries().empty()) {
      seen = true;
      ::kill(child, SIGINT);
      break;
    }
    if (::waitpid(child, &status, WNOHANG) == child) break;  // finished without being seen
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (seen) {
    ASSERT_EQ(::waitpid(child, &status, 0), child);
  }
  ASSERT_TRUE(seen) << "the bake ended before its temporary file was seen";
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of handling it";
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_EQ(cli_test::readFileText(errFile), "plenoptic: interrupted\n");
  EXPECT_TRUE(temporaries().empty());
  EXPECT_FALSE(fs::exists(path("c.plf")));
}

TEST_F(AppCli, OverflowingEmissionIsRefusedAndNeverBakedIntoAFile) {
  // An emission near FLT_MAX (refused by the scene check), and directional lights of 3e38
  // W/m² shining into the open box: one overflows floats during the iteration, two already
  // in the first shot. Each is found by the propagation, named, and no .plf is written.
  std::ofstream(path("emission.json"))
      << R"({"include_cornell": true, "materials": {"light": {"type": "lambert", "albedo": 0.78, "emission": 3e38}}})";
  const std::string sun = R"({"type": "directional", "direction": [0, 0, 1], "irradiance": 3e38})";
  std::ofstream(path("one.json")) << R"({"include_cornell": true, "lights": [)" << sun << "]}";
  std::ofstream(path("two.json")) << R"({"include_cornell": true, "lights": [)" << sun << ", " << sun << "]}";
  const std::string flags = " --preset draft --tixels-across 8 --directions 16";
  expectError("bake " + q("emission.json") + " -o " + q("e.plf") + flags, 1,
              "material 'light' has an emission (3e+38, 3e+38, 3e+38) above 1e+12");
  expectError("bake " + q("one.json") + " -o " + q("one.plf") + flags, 1,
              "one.json: light propagation overflowed in iteration 1: non-finite radiance in chart ");
  expectError("bake " + q("two.json") + " -o " + q("two.plf") + flags, 1,
              "two.json: light propagation overflowed in the first shot (direct light): non-finite radiance in chart ");
  std::string err;
  run("bake " + q("one.json") + " -o " + q("one.plf") + flags, nullptr, &err);
  EXPECT_NE(err.find("(material 'white'); the brightest emitter is directional light 0 (irradiance 3e+38 3e+38 3e+38)"),
            std::string::npos)
      << err;
  // No light field was written (the visibility fields, valid, were saved before propagation).
  EXPECT_EQ(outputs({"emission.json", "one.json", "two.json", "one.plv", "two.plv"}), std::vector<std::string>{});
}

}  // namespace
}  // namespace pl
