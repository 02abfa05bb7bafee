// The tixel-setup file (plt_file.h): round trip, the cases read as "not this bake's" and
// the corrupt ones refused with the file's name.
#include "plf/plt_file.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/hash.h"
#include "support/expect_error.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

using test_support::expectError;

class PltFileTest : public test_support::TempDirTest {
 protected:
  static constexpr uint64_t kHash = 0x1234abcd5678ef90ull;
  static constexpr uint64_t kTixels = 1000;
  std::vector<float> points = std::vector<float>(kTixels * 3);
  std::vector<uint8_t> flags = std::vector<uint8_t>(kTixels);
  std::vector<uint64_t> keys = {7, 0xffffffffffffffffull, 42};

  PltFileTest() {
    for (uint64_t i = 0; i < points.size(); ++i) points[i] = float(i) * 0.25f - 17.0f;
    for (uint64_t i = 0; i < flags.size(); ++i) flags[i] = uint8_t(i % 7 == 0);
  }

  /// Three arrays: points, an unused one, flags; and three keys.
  std::string write(const std::string& name) {
    const std::vector<TixelSetupView> views = {{{'P', 'N', 'T', 'S'}, 12, kTixels, points.data()},
                                               {{'N', 'O', 'N', 'E'}, 4, 0, nullptr},
                                               {{'F', 'L', 'A', 'G'}, 1, kTixels, flags.data()}};
    writeTixelSetupFile(path(name), kHash, kTixels, views, keys);
    return path(name);
  }

  static std::vector<unsigned char> bytesOf(const std::string& file) {
    const std::string text = test_support::readFileText(file);
    return {text.begin(), text.end()};
  }
  static void put(const std::string& file, const std::vector<unsigned char>& bytes) {
    std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(bytes.data()),
                                                                   std::streamsize(bytes.size()));
  }
  /// The file with the payload checksum recomputed (so the checks behind it are reached).
  static void putWithChecksum(const std::string& file, std::vector<unsigned char> bytes) {
    const uint64_t checksum = xxh64(bytes.data() + 48, bytes.size() - 48);
    std::memcpy(bytes.data() + 32, &checksum, 8);
    put(file, bytes);
  }
};

TEST_F(PltFileTest, RoundTripKeepsEveryByte) {
  const std::string file = write("a.plt");
  TixelSetupFile read;
  std::string why;
  ASSERT_TRUE(readTixelSetupFile(file, kHash, read, &why)) << why;
  EXPECT_EQ(read.hash, kHash);
  EXPECT_EQ(read.tixelCount, kTixels);
  ASSERT_EQ(read.arrays.size(), 3u);
  EXPECT_EQ(std::string(read.arrays[0].tag.data(), 4), "PNTS");
  EXPECT_EQ(read.arrays[0].elementBytes, 12u);
  ASSERT_EQ(read.arrays[0].bytes.size(), points.size() * sizeof(float));
  EXPECT_EQ(std::memcmp(read.arrays[0].bytes.data(), points.data(), points.size() * sizeof(float)), 0);
  EXPECT_EQ(read.arrays[1].count, 0u);
  EXPECT_TRUE(read.arrays[1].bytes.empty());
  EXPECT_EQ(read.arrays[2].bytes, std::vector<unsigned char>(flags.begin(), flags.end()));
  EXPECT_EQ(read.keys, keys);
  EXPECT_EQ(fileCount(), 1u);  // no temporary left
}

// A version 1 file (its key count was a reserved 0) reads as one without keys.
TEST_F(PltFileTest, VersionOneReadsWithoutKeys) {
  keys.clear();
  const std::string file = write("a.plt");
  std::vector<unsigned char> bytes = bytesOf(file);
  bytes[8] = 1;
  put(file, bytes);
  TixelSetupFile read;
  std::string why;
  ASSERT_TRUE(readTixelSetupFile(file, kHash, read, &why)) << why;
  EXPECT_TRUE(read.keys.empty());
  EXPECT_EQ(read.arrays[2].bytes, std::vector<unsigned char>(flags.begin(), flags.end()));
}

TEST_F(PltFileTest, AbsentStaleOrOtherVersionIsNotAnError) {
  TixelSetupFile read;
  std::string why;
  EXPECT_FALSE(readTixelSetupFile(path("none.plt"), kHash, read, &why));
  EXPECT_NE(why.find("none.plt does not exist"), std::string::npos) << why;
  const std::string file = write("a.plt");
  EXPECT_FALSE(readTixelSetupFile(file, kHash + 1, read, &why));
  EXPECT_NE(why.find("another bake"), std::string::npos) << why;
  std::vector<unsigned char> bytes = bytesOf(file);
  bytes[8] = 3;  // version 3
  put(file, bytes);
  EXPECT_FALSE(readTixelSetupFile(file, kHash, read, &why));
  EXPECT_NE(why.find("format version 3"), std::string::npos) << why;
}

TEST_F(PltFileTest, CorruptFilesAreRefusedNamingTheFile) {
  const std::vector<unsigned char> good = bytesOf(write("a.plt"));
  TixelSetupFile read;
  std::string why;
  const std::string file = path("bad.plt");
  auto refused = [&](const std::vector<unsigned char>& bytes, const std::string& problem) {
    put(file, bytes);
    expectError([&] { readTixelSetupFile(file, kHash, read, &why); }, {"bad.plt", problem});
  };
  refused({good.begin(), good.begin() + 20}, "truncated");
  std::vector<unsigned char> bytes = good;
  bytes[0] = 'X';
  refused(bytes, "bad magic");
  bytes = good;
  bytes.back() ^= 0x40u;
  refused(bytes, "checksum");
  refused({good.begin(), good.end() - 5}, "checksum");
  // Forged tables with a valid checksum: the checks behind it.
  auto forged = [&](size_t at, uint64_t value, size_t size, const std::string& problem) {
    std::vector<unsigned char> b = good;
    std::memcpy(b.data() + at, &value, size);
    putWithChecksum(file, b);
    expectError([&] { readTixelSetupFile(file, kHash, read, &why); }, {"bad.plt", problem});
  };
  forged(12, 1000, 4, "arrays declared");                 // array count
  forged(40, uint64_t(1) << 19, 8, "keys declared");      // key count
  forged(48 + 4, 0, 4, "elements of 0 bytes");             // element size
  forged(48 + 8, kTixels - 1, 8, "not 0 or the 1000 tixels");
  forged(48 + 16, 1u << 30, 8, "runs past the end");      // frame size
  forged(48 + 32 + 16, 8, 8, "inconsistent");             // a frame for an unused array
  forged(48 + 4, 8, 4, "array PNTS");                     // the frame's content size disagrees
  std::vector<unsigned char> longer = good;
  longer.push_back(0);
  putWithChecksum(file, longer);
  expectError([&] { readTixelSetupFile(file, kHash, read, &why); }, {"bad.plt", "unexpected bytes"});
}

TEST_F(PltFileTest, WriterRefusesArraysOfAnotherLength) {
  const std::vector<TixelSetupView> views = {{{'P', 'N', 'T', 'S'}, 12, kTixels - 1, points.data()}};
  expectError([&] { writeTixelSetupFile(path("a.plt"), kHash, kTixels, views); }, {"a.plt", "PNTS"});
  EXPECT_EQ(fileCount(), 0u);
}

}  // namespace
}  // namespace pl
