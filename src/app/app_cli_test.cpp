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
  expectError("", 2, "A subcommand is required");
  expectError(trace + " --no-such-flag", 2, "--no-such-flag");
  expectError(trace + " --spp", 2, "--spp");
  expectError(trace + " --spp abc", 2, "--spp");
  expectError(trace + " --spp 0", 2, "--spp");
  expectError(trace + " --strategy fast", 2, "--strategy");
  expectError(trace + " --fstop 8", 2, "--fstop/--shutter/--iso");
  expectError("trace cornell --spp 1", 2, "an output image is required");
  expectError("render " + q("a.plf") + " -o " + q("f%03d.png"), 2, "needs a camera path");
  expectError("frobnicate", 2, "A subcommand is required");
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
  std::string out;
  run("--version", &out);
  EXPECT_EQ(out, "plenoptic 0.1.0\n");
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
  // The bake: 65536 gather directions per tixel make a visibility field of many GiB.
  EXPECT_EQ(cli_test::runPlenoptic("bake cornell -o " + q("b.plf") + " --directions 65536 --quiet", dir_, &out, &err,
                                   limit),
            1)
      << err;
  EXPECT_NE(err.find("bake (visibility field and light-field values): estimated memory "), std::string::npos)
      << err;
  EXPECT_NE(err.find("lower --preset, --tixels-across or --directions"), std::string::npos) << err;
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
  EXPECT_EQ(outputs(), (std::vector<std::string>{"small.plf", "small.plv"}));
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
