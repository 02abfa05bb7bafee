// Resuming an interrupted bake (resume.h): the visibility journal — torn, damaged and foreign
// ones — and the propagation checkpoint give the uninterrupted bake's field and values bit for bit.
#include "bake/resume.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bake/parameterisation.h"
#include "bake/propagation.h"
#include "bake/shard.h"
#include "bake/visibility.h"
#include "core/progress.h"
#include "distributed/communicator.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

BakeSettings smallSettings() {
  BakeSettings s = bakePreset("draft");
  s.tixelsAcrossScene = 8;
  s.gatherDirections = 64;
  return s;
}

void expectSameField(const VisibilityField& a, const VisibilityField& b) {
  ASSERT_EQ(a.tixelCount, b.tixelCount);
  ASSERT_EQ(a.entryBytes.size(), b.entryBytes.size());
  EXPECT_EQ(std::memcmp(a.entryBytes.data(), b.entryBytes.data(), a.entryBytes.size()), 0);
  ASSERT_EQ(a.entryOffset.size(), b.entryOffset.size());
  EXPECT_TRUE(std::equal(a.entryOffset.begin(), a.entryOffset.end(), b.entryOffset.begin()));
  ASSERT_EQ(a.extraOffset.size(), b.extraOffset.size());
  EXPECT_TRUE(std::equal(a.extraOffset.begin(), a.extraOffset.end(), b.extraOffset.begin()));
  ASSERT_EQ(a.extras.size(), b.extras.size());
  EXPECT_EQ(std::memcmp(a.extras.data(), b.extras.data(), a.extras.size() * sizeof(VisibilityExtra)), 0);
  EXPECT_EQ(a.hash, b.hash);
}

class ResumeTest : public test_support::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    Progress::setEnabled(false);
  }

  const Scene scene_ = makeCornellBox();
  const BakeSettings settings_ = smallSettings();
  const Parameterisation param_ = buildParameterisation(scene_, settings_);
  const Accel accel_{scene_};
  const std::vector<TixelRange> all_{TixelRange{0, param_.tixelCount}};

  /// The field traced with a journal at `journal` (resume allowed), and the notes it made.
  VisibilityShard traceWith(const std::string& journal, std::string* notes, uint64_t* restored = nullptr,
                            const BakeSettings* settings = nullptr, bool resume = true) {
    VisibilityJournal j(journal, resume, [notes](const std::string& line) {
      if (notes) *notes += line + "\n";
    });
    VisibilityShard shard = computeVisibilityShard(scene_, accel_, param_, settings ? *settings : settings_, all_, false, &j);
    if (restored) *restored = j.restoredBlocks();
    return shard;
  }
};

// A journal cut anywhere — mid-record included, as a kill leaves it — resumes: the blocks it
// holds whole are reused, the torn record is dropped, and the field equals an uninterrupted trace.
TEST_F(ResumeTest, TornJournalResumesToTheSameField) {
  const VisibilityField reference = computeVisibility(scene_, accel_, param_, settings_);
  const std::string journal = path("box.plv.partial");
  std::string notes;
  uint64_t restored = 0;
  const VisibilityShard full = traceWith(journal, &notes, &restored);
  EXPECT_EQ(restored, 0u);
  expectSameField(full.field, reference);
  const uint64_t size = fs::file_size(journal);
  ASSERT_GT(size, 1000u);
  // The whole journal: nothing is traced again.
  notes.clear();
  const VisibilityShard again = traceWith(journal, &notes, &restored);
  EXPECT_EQ(again.field.rays, 0u);
  expectSameField(again.field, reference);
  EXPECT_NE(notes.find("resuming the interrupted trace"), std::string::npos) << notes;
  const uint64_t blocks = restored;
  for (const double fraction : {0.37, 0.81}) {
    std::filesystem::resize_file(journal, uint64_t(double(size) * fraction));
    notes.clear();
    const VisibilityShard resumed = traceWith(journal, &notes, &restored);
    EXPECT_GT(restored, 0u);
    EXPECT_LT(restored, blocks);
    EXPECT_GT(resumed.field.rays, 0u);
    EXPECT_LT(resumed.field.rays, reference.rays);
    EXPECT_NE(notes.find("torn or damaged tail"), std::string::npos) << notes;
    expectSameField(resumed.field, reference);
    // The resumed run journalled the rest: the journal is whole again.
    EXPECT_EQ(fs::file_size(journal), size);
  }
}

// A damaged byte ends the valid part of the journal at its record; the rest is traced again.
TEST_F(ResumeTest, DamagedJournalRecordIsDropped) {
  const std::string journal = path("box.plv.partial");
  const VisibilityShard full = traceWith(journal, nullptr);
  const uint64_t size = fs::file_size(journal);
  {
    std::fstream f(journal, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(size / 2));
    char c = 0;
    f.read(&c, 1);
    f.seekp(std::streamoff(size / 2));
    c = char(c ^ 0x5a);
    f.write(&c, 1);
  }
  std::string notes;
  uint64_t restored = 0;
  const VisibilityShard resumed = traceWith(journal, &notes, &restored);
  EXPECT_GT(restored, 0u);
  EXPECT_GT(resumed.field.rays, 0u);
  EXPECT_NE(notes.find("torn or damaged tail"), std::string::npos) << notes;
  expectSameField(resumed.field, full.field);
}

// A journal of other settings, a file that is not a journal, or --fresh: traced afresh,
// with the reason in the notes, never an error.
TEST_F(ResumeTest, ForeignOrDamagedJournalIsTracedAfresh) {
  const std::string journal = path("box.plv.partial");
  BakeSettings otherSeed = settings_;
  otherSeed.seed = 7;
  (void)traceWith(journal, nullptr, nullptr, &otherSeed);
  std::string notes;
  uint64_t restored = 1;
  const VisibilityShard traced = traceWith(journal, &notes, &restored);
  EXPECT_EQ(restored, 0u);
  EXPECT_NE(notes.find("tracing afresh, because"), std::string::npos) << notes;
  EXPECT_NE(notes.find("different geometry, parameterisation or settings"), std::string::npos) << notes;
  expectSameField(traced.field, computeVisibility(scene_, accel_, param_, settings_));

  { std::ofstream(journal, std::ios::binary | std::ios::trunc) << "not a journal at all, but long enough to hold a header"; }
  notes.clear();
  (void)traceWith(journal, &notes, &restored);
  EXPECT_EQ(restored, 0u);
  EXPECT_NE(notes.find("damaged header"), std::string::npos) << notes;

  notes.clear();
  (void)traceWith(journal, &notes, &restored, nullptr, /*resume=*/false);
  EXPECT_EQ(restored, 0u);
  EXPECT_NE(notes.find("ignoring the partial field"), std::string::npos) << notes;
}

// Propagation resumed from the state after iteration k (in memory and through the file)
// ends with the uninterrupted propagation's values and iteration count, bit for bit.
TEST_F(ResumeTest, PropagationResumesFromACheckpoint) {
  const VisibilityShard vis = VisibilityShard::whole(computeVisibility(scene_, accel_, param_, settings_));
  SingleProcess single;
  const ShardPlan plan = planShards(scene_, param_, settings_, 1);
  const std::string file = path("box.plv.checkpoint");
  const uint64_t key = propagationKey(vis.field.hash, scene_, settings_);
  constexpr uint32_t kStopAfter = 2;
  PropagationOptions saving;
  uint32_t saves = 0;
  saving.save = [&](const PropagationProgress& at, const TransportState& state) {
    ++saves;
    if (at.iterations != kStopAfter) return;
    PropagationProgress progress = at;
    progress.key = key;
    writePropagationCheckpoint(file, progress, state.direct, state.punctualGlossy, state.current);
  };
  auto field = [&]() -> const VisibilityShard& { return vis; };
  const PropagationResult full = propagate(scene_, accel_, param_, field, settings_, single, plan, saving);
  ASSERT_GT(full.iterations, kStopAfter);
  EXPECT_EQ(saves, full.iterations);

  PropagationCheckpoint checkpoint;
  std::string why;
  ASSERT_TRUE(readPropagationCheckpoint(file, key, param_.valueCount, checkpoint, &why)) << why;
  EXPECT_EQ(checkpoint.progress.iterations, kStopAfter);
  EXPECT_FALSE(checkpoint.progress.converged);
  PropagationOptions resuming;
  resuming.from = &checkpoint;
  const PropagationResult resumed = propagate(scene_, accel_, param_, field, settings_, single, plan, resuming);
  EXPECT_EQ(resumed.iterations, full.iterations);
  EXPECT_EQ(resumed.residual, full.residual);
  EXPECT_EQ(resumed.shadowRays, full.shadowRays);
  ASSERT_EQ(resumed.values.size(), full.values.size());
  EXPECT_EQ(std::memcmp(resumed.values.data(), full.values.data(), full.values.size() * sizeof(Rgb)), 0);

  // Another bake's key, another value count, damage: not resumed, with the reason.
  EXPECT_FALSE(readPropagationCheckpoint(file, key ^ 1, param_.valueCount, checkpoint, &why));
  EXPECT_NE(why.find("another scene"), std::string::npos) << why;
  EXPECT_FALSE(readPropagationCheckpoint(file, key, param_.valueCount + 1, checkpoint, &why));
  EXPECT_NE(why.find("values"), std::string::npos) << why;
  std::filesystem::resize_file(file, fs::file_size(file) - 1);
  EXPECT_FALSE(readPropagationCheckpoint(file, key, param_.valueCount, checkpoint, &why));
  EXPECT_NE(why.find("damaged"), std::string::npos) << why;
  EXPECT_FALSE(readPropagationCheckpoint(path("absent.checkpoint"), key, param_.valueCount, checkpoint, &why));
}

// The checkpoint's key follows what the propagation depends on beyond the field: materials
// (an albedo, an emission) and every bake setting.
TEST_F(ResumeTest, CheckpointKeyFollowsSceneAndSettings) {
  const uint64_t key = propagationKey(1, scene_, settings_);
  EXPECT_EQ(propagationKey(1, scene_, settings_), key);
  EXPECT_NE(propagationKey(2, scene_, settings_), key);
  BakeSettings tighter = settings_;
  tighter.tolerance *= 0.5f;
  EXPECT_NE(propagationKey(1, scene_, tighter), key);
  Scene brighter = makeCornellBox();
  for (Material& m : brighter.materials)
    if (m.isEmissive()) m.emission *= 2.0f;
  EXPECT_NE(propagationKey(1, brighter, settings_), key);
}

}  // namespace
}  // namespace pl
