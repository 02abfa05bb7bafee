// Bad scene files through the `plenoptic` command (PLENOPTIC_BINARY), as a user meets them:
// the inputs fuzzing found to crash the program or to end it with an internal error now give
// `plenoptic: error: FILE…: problem`, exit status 1 and no output.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

class SceneCliTest : public cli_test::CliTest {
 protected:
  /// Traces `scene` (a file of the fuzzing regression corpus) and expects a clean error
  /// containing `message`.
  void expectCleanError(const std::string& scene, const std::string& message) {
    const std::string file = std::string(PLENOPTIC_TEST_DATA_DIR) + "/fuzz/" + scene;
    const std::string out = path("out.exr");
    std::string err;
    EXPECT_EQ(run("trace \"" + file + "\" -o " + out + " --width 8 --height 8 --spp 1", nullptr, &err), 1) << err;
    EXPECT_EQ(err.rfind("plenoptic: error: ", 0), 0u) << err;
    EXPECT_NE(err.find(message), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out));
  }
};

TEST_F(SceneCliTest, ObjFaceWithAnEmptyIndexIsAnErrorWithTheLineNotACrash) {
  expectCleanError("obj/empty_texcoord_index.obj", "empty_texcoord_index.obj:2: empty texture coordinate index");
  expectCleanError("obj/empty_texcoord_index_middle.obj", "empty_texcoord_index_middle.obj:4: empty texture coordinate index");
  expectCleanError("obj/empty_normal_index.obj", "empty_normal_index.obj:2: empty normal index");
}

TEST_F(SceneCliTest, LibraryExceptionsAreCleanErrorsNotInternalOnes) {
  expectCleanError("json_scene/number_overflow.json", "number_overflow.json: malformed JSON");
  expectCleanError("gltf/zero_length_buffer.glb", "zero_length_buffer.glb: not a valid glTF file");
}

}  // namespace
}  // namespace pl
