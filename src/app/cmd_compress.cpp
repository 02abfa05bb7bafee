// `plenoptic compress IN.plf -o OUT.plf --mode none|lossless|bc1|hdr`: rewrites a light
// field with its values stored in another mode (plf/compression.h), atomically, and
// reports sizes, the ratio, encode and decode times and the error of the decoded values
// against the input's.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/timing.h"
#include "plf/compression.h"
#include "plf/plf_file.h"

namespace pl {
namespace {

struct CompressOptions {
  std::string input;
  std::string output;
  std::string mode = "lossless";
  std::string statsPath;  ///< --stats: the figures as JSON
  ValuesCodecOptions codec;  ///< --hdr-steps, --zstd-level
};

const PlfSectionInfo& valuesSection(const PlfInfo& info) {
  for (const PlfSectionInfo& s : info.sections)
    if (s.id == "VALS") return s;
  fail("{}: no values section", info.path);  // readLightFieldInfo refuses such files already
}

void runCompress(const CompressOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  const ValuesCodec codec = parseValuesCodec(options.mode);
  // Unwritable outputs fail before the work, as in trace, bake and render.
  checkOutputPath(options.output, {".plf"}, "-o");
  if (!options.statsPath.empty()) checkOutputPath(options.statsPath, {}, "--stats");
  checkDistinctOutputs({{"-o", options.output}, {"--stats", options.statsPath}});
  const PlfInfo inputInfo = readLightFieldInfo(options.input, /*verifyChecksums=*/false);
  const PlfSectionInfo inputValues = valuesSection(inputInfo);

  auto start = std::chrono::steady_clock::now();
  const LightField lf = readLightField(options.input);
  const double inputReadSeconds = secondsSince(start);

  start = std::chrono::steady_clock::now();
  writeLightField(options.output, lf, codec, options.codec);
  const double writeSeconds = secondsSince(start);

  // Read the result back as every reader will (readLightField decodes): the median of
  // kDecodeRuns reads is the decode time, and the decoded values give the error.
  constexpr int kDecodeRuns = 5;
  std::vector<double> readTimes;
  LightField back;
  for (int run = 0; run < kDecodeRuns; ++run) {
    start = std::chrono::steady_clock::now();
    back = readLightField(options.output);
    readTimes.push_back(secondsSince(start));
  }
  std::nth_element(readTimes.begin(), readTimes.begin() + kDecodeRuns / 2, readTimes.end());
  const double readSeconds = readTimes[kDecodeRuns / 2];
  const ValuesError error = measureValuesError(lf.values, back.values);
  const bool bitExact =
      lf.values.size() == back.values.size() &&
      std::equal(lf.values.begin(), lf.values.end(), back.values.begin(), [](const Rgb& a, const Rgb& b) {
        return std::memcmp(&a, &b, sizeof(Rgb)) == 0;
      });

  const PlfInfo outputInfo = readLightFieldInfo(options.output, /*verifyChecksums=*/false);
  const PlfSectionInfo outputValues = valuesSection(outputInfo);
  const double valuesRatio = outputValues.storedSize > 0 ? double(outputValues.decodedSize) / double(outputValues.storedSize) : 0.0;
  // The whole file against the same light field stored raw (up to ≤ 63 bytes of alignment per
  // section): every section's decoded size in place of its stored one.
  uint64_t rawFileBytes = outputInfo.fileBytes;
  for (const PlfSectionInfo& section : outputInfo.sections) rawFileBytes += section.decodedSize - section.storedSize;
  const double fileRatio = double(rawFileBytes) / double(outputInfo.fileBytes);

  if (!options.statsPath.empty()) {
    nlohmann::json json;
    json["command"] = "compress";
    json["input"] = options.input;
    json["output"] = options.output;
    json["input_mode"] = std::string(valuesCodecName(ValuesCodec(inputValues.encoding)));
    json["mode"] = std::string(valuesCodecName(codec));
    json["hdr_steps_per_stop"] = options.codec.hdrStepsPerStop;
    json["zstd_level"] = options.codec.zstdLevel;
    json["threads"] = runtime.threads();
    json["values"] = lf.values.size();
    json["input_file_bytes"] = inputInfo.fileBytes;
    json["file_bytes"] = outputInfo.fileBytes;
    json["raw_file_bytes"] = rawFileBytes;
    json["values_stored_bytes"] = outputValues.storedSize;
    json["values_decoded_bytes"] = outputValues.decodedSize;
    json["values_ratio"] = valuesRatio;
    json["file_ratio"] = fileRatio;
    json["input_read_seconds"] = inputReadSeconds;
    json["encode_write_seconds"] = writeSeconds;
    json["decode_read_seconds"] = readSeconds;
    json["bit_exact"] = bitExact;
    json["values_rmse"] = error.rmse;
    json["values_relative_rmse"] = error.relativeRmse;
    json["values_max_relative_error"] = error.maxRelative;
    writeFileAtomically(options.statsPath, json.dump(2) + "\n");
  }
  fmt::print("wrote {} ({} values): values {} → {} bytes ({}, {:.2f}:1), file {} bytes ({:.2f}:1 against raw); "
             "encode+write {:.3f} s, read+decode {:.3f} s; {}\n",
             options.output, lf.values.size(), outputValues.decodedSize, outputValues.storedSize, valuesCodecName(codec),
             valuesRatio, outputInfo.fileBytes, fileRatio, writeSeconds, readSeconds,
             bitExact ? std::string("bit-exact")
                      : fmt::format("value error: RMSE {:.4g}, relative RMSE {:.4g}, max relative {:.4g}", error.rmse,
                                    error.relativeRmse, error.maxRelative));
}

}  // namespace

void addCompressCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<CompressOptions>();
  CLI::App* command = app.add_subcommand(
      "compress", "Rewrite a light field (.plf) with its values stored as none|lossless|bc1|hdr; reports ratio and error");
  command->add_option("input", options->input, "Input light field (.plf), any mode")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--output", options->output, "Output light field (.plf); may equal the input (atomic write)")
      ->required();
  command->add_option("--mode", options->mode,
                      "none (float32), lossless (bit-exact: MED prediction + zstd), bc1 (S3TC of tone-mapped "
                      "values), hdr (log codes, 0.54% max relative error at 64 steps per stop)")
      ->check(CLI::IsMember({"none", "lossless", "bc1", "hdr"}))
      ->capture_default_str();
  command->add_option("--stats", options->statsPath, "Write sizes, ratio, times and errors as JSON");
  command->add_option("--hdr-steps", options->codec.hdrStepsPerStop,
                      "hdr: logarithmic steps per factor of 2 (max relative error 2^(1/(2·steps)) − 1)")
      ->check(CLI::Range(1, 200))
      ->capture_default_str();
  command->add_option("--zstd-level", options->codec.zstdLevel, "lossless, bc1, hdr: zstd compression level")
      ->check(CLI::Range(1, 22))
      ->capture_default_str();
  command->callback([options, &global] { runCompress(*options, global); });
}

}  // namespace pl
