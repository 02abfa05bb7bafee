#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/cancel.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "core/interrupt.h"
#include "core/math.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/timing.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

TEST(Frame, IsOrthonormalAndRoundTrips) {
  Pcg32 rng(1, 2);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 n = sampleUniformSphere({rng.uniform(), rng.uniform()});
    const Frame f = Frame::fromNormal(n);
    // 1e-5: a few float ulps (~6e-8 each) of the products in fromNormal; the sampled n itself
    // is unit length only to ~1e-7.
    EXPECT_NEAR(glm::dot(f.s, f.t), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(f.s, f.n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.s), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.t), 1.0f, 1e-5f);
    const Vec3 v = sampleUniformSphere({rng.uniform(), rng.uniform()});
    const Vec3 back = f.toWorld(f.toLocal(v));
    EXPECT_NEAR(glm::length(back - v), 0.0f, 1e-5f);
    EXPECT_GT(glm::dot(glm::cross(f.s, f.t), f.n), 0.99f);  // right-handed
  }
}

TEST(Pcg32, SameKeySameStreamDifferentKeysDiffer) {
  Pcg32 a = Pcg32::forKey(5, 7, 1), b = Pcg32::forKey(5, 7, 1), c = Pcg32::forKey(5, 8, 1);
  int same = 0;
  for (int i = 0; i < 100; ++i) {
    const uint32_t x = a.next();
    EXPECT_EQ(x, b.next());
    same += x == c.next();
  }
  EXPECT_LT(same, 3);
}

TEST(Pcg32, UniformMeanAndRange) {
  Pcg32 rng(42, 54);
  double sum = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const float u = rng.uniform();
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    sum += u;
  }
  // Standard error of the mean of U(0,1) is sqrt(1/12/n) ≈ 6.5e-4; allow 5 sigma.
  EXPECT_NEAR(sum / n, 0.5, 5 * std::sqrt(1.0 / 12.0 / n));
}

TEST(Sampling, InverseConcentricDiskUndoesTheConcentricMap) {
  Pcg32 rng(11, 3);
  for (int i = 0; i < 10000; ++i) {
    const Vec2 u(rng.uniform(), rng.uniform());
    const Vec2 back = inverseConcentricDisk(sampleConcentricDisk(u));
    EXPECT_NEAR(back.x, u.x, 2e-5f) << u.x << "," << u.y;
    EXPECT_NEAR(back.y, u.y, 2e-5f) << u.x << "," << u.y;
  }
  EXPECT_NEAR(inverseConcentricDisk(Vec2(0.0f)).x, 0.5f, 1e-6f);
}

TEST(Sampling, CosineHemisphereHasTheCosineDensity) {
  // cos θ / cosineHemispherePdf(cos θ) = π holds by algebra for any direction, so it cannot
  // test the sampler. Test the distribution instead: under pdf = cos θ/π,
  //   E[cos θ]  = ∫ cos²θ/π dω = 2/3,   E[cos²θ] = ∫ cos³θ/π dω = 1/2,
  // so Var[cos θ] = 1/2 − 4/9 = 1/18 (a uniform-hemisphere sampler would give E[cos θ] = 1/2).
  Pcg32 rng(3, 4);
  const int n = 100000;
  double sumCos = 0.0;
  for (int i = 0; i < n; ++i) {
    const Vec3 w = sampleCosineHemisphere({rng.uniform(), rng.uniform()});
    ASSERT_NEAR(glm::length(w), 1.0f, 1e-5f);  // float round-off of sqrt(1 − x² − y²)
    ASSERT_GE(w.z, 0.0f);
    sumCos += w.z;
  }
  // Standard error sqrt(1/18/n) ≈ 7.5e-4; allow 5 sigma.
  EXPECT_NEAR(sumCos / n, 2.0 / 3.0, 5.0 * std::sqrt(1.0 / 18.0 / n));
  EXPECT_NEAR(cosineHemispherePdf(0.5f), 0.5f / kPi, 1e-7f);  // the pdf formula itself
  EXPECT_EQ(cosineHemispherePdf(-0.1f), 0.0f);                  // no density below the surface
}

TEST(Distribution1D, SamplesProportionallyToWeights) {
  const std::vector<float> w = {1.0f, 0.0f, 3.0f};
  Distribution1D d(w);
  EXPECT_FLOAT_EQ(d.probability(0), 0.25f);
  EXPECT_FLOAT_EQ(d.probability(1), 0.0f);
  EXPECT_FLOAT_EQ(d.probability(2), 0.75f);
  EXPECT_EQ(d.sample(0.1f), 0u);
  EXPECT_EQ(d.sample(0.3f), 2u);
  float remapped = -1;
  d.sample(0.625f, &remapped);
  EXPECT_NEAR(remapped, 0.5f, 1e-6f);
}


// --- core/file_io.h: atomic writes ---

/// A fresh empty directory per test; entries() lists it, hidden temporaries included.
class AtomicWriteTest : public test_support::TempDirTest {
 protected:
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    return names;
  }
  static std::string contents(const std::string& file) { return test_support::readFileText(file); }
};

TEST_F(AtomicWriteTest, WritesAndReplacesContentLeavingNoTemporary) {
  const std::string target = path("out.json");
  writeFileAtomically(target, std::string_view("first version, longer than the second\n"));
  EXPECT_EQ(contents(target), "first version, longer than the second\n");
  writeFileAtomically(target, std::string_view("second\n"), FileSync::durable);
  EXPECT_EQ(contents(target), "second\n");  // replaced, not overwritten in place (no old tail)
  EXPECT_EQ(entries(), std::vector<std::string>{"out.json"});
}

TEST_F(AtomicWriteTest, FailureKeepsTheOldFileAndRemovesTheTemporary) {
  const std::string target = path("image.exr");
  writeFileAtomically(target, std::string_view("old"));
  std::string temporarySeen;
  try {
    writeFileAtomically(target, [&](const std::string& temporary) {
      temporarySeen = temporary;
      std::ofstream(temporary) << "half of the new";
      ASSERT_TRUE(std::filesystem::exists(temporary));
      fail("encoder gave up");
    });
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(target), std::string::npos) << message;
    EXPECT_NE(message.find("encoder gave up"), std::string::npos) << message;
  }
  EXPECT_EQ(std::filesystem::path(temporarySeen).parent_path(), dir_);  // beside the target: same file system
  EXPECT_FALSE(std::filesystem::exists(temporarySeen));
  EXPECT_EQ(contents(target), "old");
  EXPECT_EQ(entries(), std::vector<std::string>{"image.exr"});
}

TEST_F(AtomicWriteTest, FailureOnANewTargetLeavesNothing) {
  EXPECT_THROW(writeFileAtomically(path("new.plf"),
                                   [](const std::string& temporary) {
                                     std::ofstream(temporary) << "partial";
                                     throw std::runtime_error("disk full");
                                   }),
               Error);
  EXPECT_TRUE(entries().empty());
}

TEST_F(AtomicWriteTest, MissingDirectoryOrDirectoryTargetIsAnErrorNamingTheFile) {
  const std::string inMissing = path("missing/out.png");
  try {
    writeFileAtomically(inMissing, std::string_view("x"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(inMissing), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  std::filesystem::create_directory(path("sub"));
  EXPECT_THROW(writeFileAtomically(path("sub"), std::string_view("x")), Error);
  EXPECT_EQ(entries(), std::vector<std::string>{"sub"});
  EXPECT_TRUE(std::filesystem::is_empty(path("sub")));
}

TEST_F(AtomicWriteTest, UncommittedPendingFileIsRemoved) {
  const std::string target = path("video.mp4");
  std::string temporary;
  {
    PendingFile pending(target);
    temporary = pending.temporaryPath();
    std::ofstream(temporary) << "frames";
    EXPECT_TRUE(std::filesystem::exists(temporary));
  }  // e.g. an exception between the frames: never committed
  EXPECT_FALSE(std::filesystem::exists(temporary));
  EXPECT_TRUE(entries().empty());
  {
    PendingFile pending(target);
    std::ofstream(pending.temporaryPath()) << "all frames";
    pending.commit();
  }
  EXPECT_EQ(contents(target), "all frames");
  EXPECT_EQ(entries(), std::vector<std::string>{"video.mp4"});
}

TEST_F(AtomicWriteTest, MappedFileSeesTheBytesAndOutlivesAReplacement) {
  const std::string file = path("field.plv");
  std::string bytes(1 << 20, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 2654435761u >> 24);
  writeFileAtomically(file, std::string_view(bytes));
  const MappedFile mapped(file);
  ASSERT_EQ(mapped.bytes().size(), bytes.size());
  EXPECT_EQ(std::memcmp(mapped.bytes().data(), bytes.data(), bytes.size()), 0);
  // A new version renamed over the file (how every writer here replaces files) leaves the
  // mapped old version intact.
  writeFileAtomically(file, std::string_view("new"));
  EXPECT_EQ(std::memcmp(mapped.bytes().data(), bytes.data(), bytes.size()), 0);
  EXPECT_EQ(MappedFile(file).bytes().size(), 3u);
  writeFileAtomically(path("empty"), std::string_view());
  EXPECT_TRUE(MappedFile(path("empty")).bytes().empty());
  try {
    MappedFile missing(path("missing.plv"));
    FAIL() << "no error for a missing file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.plv: cannot open for reading"), std::string::npos) << e.what();
  }
}

TEST(Timing, MedianOfOddEvenAndNoValues) {
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);       // unsorted input, odd count: the middle one
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);  // even count: mean of the two middle ones
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(median({7.0}), 7.0);
}

TEST(Timing, SecondsSinceMeasuresElapsedWallTime) {
  const auto start = SteadyClock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const double seconds = secondsSince(start);
  EXPECT_GE(seconds, 0.020);  // sleep_for waits at least the duration asked for
  EXPECT_LT(seconds, 5.0);    // generous bound for a loaded machine; catches unit mix-ups (ms vs s)
}

// --- core/file_io.h: output and input checks ---

TEST_F(AtomicWriteTest, CheckOutputPathRefusesWrongExtensionsDirectoriesAndMissingDirectories) {
  auto message = [](const std::function<void()>& check) {
    try {
      check();
    } catch (const UsageError& e) {
      return "usage: " + std::string(e.what());
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([&] { checkOutputPath(path("out.plf"), {".plf"}, "-o"); }), "no error");
  EXPECT_EQ(message([&] { checkOutputPath(path("OUT.PLF"), {".plf"}, "-o"); }), "no error");  // case-insensitive
  EXPECT_EQ(message([&] { checkOutputPath("stats.json", {}, "--stats"); }), "no error");  // working directory
  EXPECT_EQ(message([&] { checkOutputPath(path("out.exr"), {".plf"}, "-o"); }),
            "usage: -o " + path("out.exr") + ": expected a .plf file name, not '.exr'");
  EXPECT_EQ(message([&] { checkOutputPath(path("out"), {".exr", ".pfm", ".png"}, "-o"); }),
            "usage: -o " + path("out") + ": expected a .exr, .pfm or .png file name, not 'no extension'");
  std::filesystem::create_directory(path("renders.plf"));
  EXPECT_EQ(message([&] { checkOutputPath(path("renders.plf"), {".plf"}, "-o"); }),
            "-o " + path("renders.plf") + ": is a directory");
  EXPECT_EQ(message([] { checkOutputPath("/no/such/dir/out.exr", {}, "-o"); }),
            "-o /no/such/dir/out.exr: directory '/no/such/dir' does not exist");
  writeFileAtomically(path("file"), std::string_view("x"));
  EXPECT_EQ(message([&] { checkOutputPath(path("file/s.json"), {}, "--stats"); }),
            "--stats " + path("file/s.json") + ": '" + path("file") + "' is not a directory");
  ASSERT_EQ(::mkfifo(path("pipe.png").c_str(), 0600), 0);
  EXPECT_EQ(message([&] { checkOutputPath(path("pipe.png"), {".png"}, "-o"); }),
            "-o " + path("pipe.png") + ": exists and is not a regular file");
  // A directory without write permission (root may write anyway, so only checked for others).
  std::filesystem::create_directory(path("readonly"));
  std::filesystem::permissions(path("readonly"), std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  if (::geteuid() != 0) {
    EXPECT_NE(message([&] { checkOutputPath(path("readonly/a.png"), {".png"}, "-o"); }).find("cannot write in directory"),
              std::string::npos);
  }
  std::filesystem::permissions(path("readonly"), std::filesystem::perms::owner_all);
}

// A file that cannot be written or read is a FileError naming it (the Python module's
// OSError); a wrong request is not.
TEST_F(AtomicWriteTest, FileProblemsAreFileErrorsNamingTheFile) {
  auto filePath = [](const std::function<void()>& call) {
    try {
      call();
    } catch (const FileError& e) {
      return e.path();
    } catch (const Error&) {
      return std::string("other error");
    }
    return std::string("no error");
  };
  EXPECT_EQ(filePath([] { checkOutputPath("/no/such/dir/out.exr", {}, "-o"); }), "/no/such/dir/out.exr");
  std::filesystem::create_directory(path("dir.plf"));
  EXPECT_EQ(filePath([&] { checkOutputPath(path("dir.plf"), {".plf"}, "-o"); }), path("dir.plf"));
  EXPECT_EQ(filePath([&] { writeFileAtomically(path("dir.plf"), std::string_view("x")); }), path("dir.plf"));
  ASSERT_EQ(::mkfifo(path("pipe.exr").c_str(), 0600), 0);
  EXPECT_EQ(filePath([&] { requireRegularFile(path("pipe.exr")); }), path("pipe.exr"));
  EXPECT_EQ(filePath([&] { checkOutputPath(path("out.exr"), {".plf"}, "-o"); }), "other error");  // a usage error
}

TEST_F(AtomicWriteTest, CheckDistinctOutputsComparesResolvedPaths) {
  std::filesystem::create_directory(path("sub"));
  EXPECT_NO_THROW(checkDistinctOutputs({{"-o", path("a.plf")}, {"--visibility", path("a.plv")}, {"--stats", ""}}));
  EXPECT_NO_THROW(checkDistinctOutputs({{"-o", ""}, {"--stats", ""}}));
  try {
    checkDistinctOutputs({{"-o", path("a.plf")}, {"--stats", ""}, {"--visibility", path("sub/../a.plf")}});
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "-o " + path("a.plf") + " and --visibility " + path("sub/../a.plf") +
                                         " are the same file: one output would overwrite the other");
  }
}

TEST_F(AtomicWriteTest, ReadersRefuseNonRegularFilesWithoutOpeningThem) {
  ASSERT_EQ(::mkfifo(path("fifo.plv").c_str(), 0600), 0);
  std::filesystem::create_directory(path("dir.plv"));
  auto message = [](const std::string& file) {
    try {
      const MappedFile mapped(file);  // would block in open(2) on the FIFO without the check
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(path("fifo.plv")), path("fifo.plv") + ": not a regular file (a FIFO)");
  EXPECT_EQ(message(path("dir.plv")), path("dir.plv") + ": not a regular file (a directory)");
  EXPECT_EQ(message("/dev/null"), "/dev/null: not a regular file (a character device)");
  EXPECT_NO_THROW(requireRegularFile(path("missing")));  // the reader's own open reports it
  writeFileAtomically(path("regular"), std::string_view("x"));
  EXPECT_NO_THROW(requireRegularFile(path("regular")));
}

// --- core/cancel.h ---

TEST_F(AtomicWriteTest, CancellationStopsParallelLoopsAndRemovesUncommittedOutputs) {
  // A loop whose ranges request cancellation once a quarter of the work is done: the rest is
  // never started (a cancellation point opens every sub-range) and pl::Cancelled reaches the caller.
  struct ClearAtExit {
    ~ClearAtExit() { clearCancellation(); }  // whatever happens, later tests run uncancelled
  } clearAtExit;
  std::atomic<uint64_t> done{0};
  const uint64_t count = 100000;
  EXPECT_THROW(parallelForRange(count, 1,
                                [&](uint64_t begin, uint64_t end) {
                                  if (done.fetch_add(end - begin) + (end - begin) >= count / 4) requestCancellation();
                                }),
               Cancelled);
  EXPECT_LT(done.load(), count);
  // An atomic write cancelled from inside stays a cancellation (not "cannot write"), and the
  // old file and no temporary remain.
  writeFileAtomically(path("out.plv"), std::string_view("old"));
  EXPECT_THROW(writeFileAtomically(path("out.plv"),
                                   [&](const std::string& temporary) {
                                     writeFileBytes(temporary, "half", 4);
                                     throwIfCancelled();
                                   }),
               Cancelled);
  EXPECT_EQ(contents(path("out.plv")), "old");
  EXPECT_EQ(entries(), std::vector<std::string>{"out.plv"});
  // Cleared, loops run to their end again.
  clearCancellation();
  done = 0;
  parallelForRange(count, 1, [&](uint64_t begin, uint64_t end) { done += end - begin; });
  EXPECT_EQ(done.load(), count);
}

// --- core/interrupt.h ---

TEST_F(AtomicWriteTest, InterruptRemovesPendingTemporariesAndExitsWith128PlusTheSignal) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const std::string target = path("out.plv");
    const std::string marker = path("temporary-name");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      // The child: what a command does while writing a large output.
      installInterruptHandlers();
      PendingFile pending(target);
      std::ofstream(pending.temporaryPath()) << "half of the visibility field";
      std::ofstream(marker) << pending.temporaryPath();
      ::raise(signal);
      ::_exit(0);  // not reached: the handler exits
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of handling it";
    EXPECT_EQ(WEXITSTATUS(status), 128 + signal);
    const std::string temporary = contents(marker);
    EXPECT_FALSE(temporary.empty());
    EXPECT_FALSE(std::filesystem::exists(temporary)) << "left behind: " << temporary;
    EXPECT_FALSE(std::filesystem::exists(target));
    std::filesystem::remove(marker);
  }
  EXPECT_TRUE(entries().empty());
}

// --- core/memory.h ---

TEST(Memory, AvailableMemoryIsKnownAndTheGuardNamesEstimateAndFlags) {
  const std::optional<uint64_t> available = availableMemoryBytes();
  ASSERT_TRUE(available.has_value());  // Linux: /proc/meminfo
  EXPECT_GT(*available, 0u);
  EXPECT_GE(peakRssBytes(), 1u << 20);  // this test binary takes more than a megabyte
  EXPECT_NO_THROW(requireMemory(1 << 20, "test", "lower --size"));
  try {
    requireMemory(uint64_t(1) << 62, "trace at 9x9", "lower --width/--height");
    FAIL() << "4 EiB were accepted";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("trace at 9x9: estimated memory 4294967296.00 GiB exceeds the ", 0), 0u) << m;
    EXPECT_NE(m.find(" GiB available; lower --width/--height"), std::string::npos) << m;
  }
}

TEST(Memory, AUsersCapIsRespectedBelowTheAvailableMemory) {
  EXPECT_NO_THROW(requireMemory(1 << 20, "test", "lower --size", uint64_t(2) << 20));
  try {
    requireMemory(uint64_t(3) << 30, "bake", "lower --preset", uint64_t(1) << 30);
    FAIL() << "3 GiB were accepted under a 1 GiB cap";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "bake: estimated memory 3.00 GiB exceeds --max-memory 1.00 GiB; lower --preset");
  }
}

TEST(Memory, MemorySizesParseWithBinaryUnits) {
  EXPECT_EQ(parseMemorySize("1073741824", "--max-memory"), uint64_t(1) << 30);
  EXPECT_EQ(parseMemorySize("800M", "--max-memory"), uint64_t(800) << 20);
  EXPECT_EQ(parseMemorySize("12G", "--max-memory"), uint64_t(12) << 30);
  EXPECT_EQ(parseMemorySize("12gib", "--max-memory"), uint64_t(12) << 30);
  EXPECT_EQ(parseMemorySize("1.5GB", "--max-memory"), uint64_t(3) << 29);
  EXPECT_EQ(parseMemorySize("2T", "--max-memory"), uint64_t(2) << 40);
  for (const char* bad : {"", "G", "lots", "-1G", "12X", "1e9", "12 G", "512K", "0"}) {
    try {
      parseMemorySize(bad, "--max-memory");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("--max-memory: '" + std::string(bad) + "' is not a memory size"), std::string::npos)
          << e.what();
    }
  }
}

// --- XXH64 (core/hash.h) ---------------------------------------------------------------------------------

TEST(Xxh64, MatchesReferenceVectors) {
  // Reference values from the xxhashjs implementation of XXH64 (seeds 0 and 42). The inputs
  // cover the short path (< 32 bytes: 0, 1, 3, 39 bytes → tail of 8-, 4- and 1-byte steps)
  // and the four-lane stripe loop (62 bytes).
  struct Vector {
    const char* text;
    uint64_t seed0, seed42;
  };
  const Vector vectors[] = {
      {"", 0xef46db3751d8e999ull, 0x98b1582b0977e704ull},
      {"a", 0xd24ec4f1a98c6e5bull, 0x88e4fe59adf7b0ccull},
      {"abc", 0x44bc2cf5ad770999ull, 0x13c1d910702770e6ull},
      {"Nobody inspects the spammish repetition", 0xfbcea83c8a378bf1ull, 0x44582824ca1018b5ull},
      {"0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ", 0x7639d419de614eedull,
       0xe023c8f961330a31ull},
  };
  for (const Vector& v : vectors) {
    EXPECT_EQ(xxh64(v.text, std::strlen(v.text), 0), v.seed0) << v.text;
    EXPECT_EQ(xxh64(v.text, std::strlen(v.text), 42), v.seed42) << v.text;
  }
}

TEST(Xxh64, StreamingInAnyPiecesEqualsOneShot) {
  std::vector<unsigned char> data(1000);
  for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>(i * 131 + 7);
  const uint64_t expected = xxh64(data.data(), data.size(), 5);
  for (size_t piece : {1, 3, 7, 31, 32, 33, 64, 999}) {
    Xxh64Stream stream(5);
    for (size_t at = 0; at < data.size(); at += piece) stream.update(data.data() + at, std::min(piece, data.size() - at));
    EXPECT_EQ(stream.digest(), expected) << "pieces of " << piece;
  }
}

}  // namespace
}  // namespace pl
