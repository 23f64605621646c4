// Robustness matrix, TUM folders given to `relight replay`: every broken folder, list or image is
// one error line naming the file (and line), exit 1, no crash or hang, nothing unfinished in --out.
#include <gtest/gtest.h>

#include "inputs.h"
#include "outcome_checks.h"
#include "relight/core/image_io.h"

namespace relight::robustness {
namespace {

// Replays a folder on the CPU (no Vulkan start-up: these rows are about reading the input).
RunOutcome replay(const std::filesystem::path& sequence, const std::filesystem::path& out,
                  std::vector<std::string> extra = {}) {
  std::vector<std::string> arguments{"replay", "--quiet", "--cpu", sequence.string(), "--out", out.string()};
  arguments.insert(arguments.end(), extra.begin(), extra.end());
  return run_relight(arguments);
}

class SequenceRobustness : public ::testing::Test {
 protected:
  test::TempDir dir;
  const std::filesystem::path out = dir.path() / "out";
};

TEST_F(SequenceRobustness, MissingFolder) {
  const auto missing = dir.path() / "no_such_sequence";
  expect_clean_error(replay(missing, out), 1, missing.string(), out);
}

TEST_F(SequenceRobustness, EmptyFolder) {
  const auto empty = dir.path() / "empty";
  std::filesystem::create_directories(empty);
  expect_clean_error(replay(empty, out), 1, (empty / "rgb.txt").string(), out);
}

TEST_F(SequenceRobustness, ListsWithoutFrames) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  write_file_atomically(sequence / "depth.txt", std::string_view("# depth maps\n"));
  expect_clean_error(replay(sequence, out), 1, sequence.string(), out);
}

TEST_F(SequenceRobustness, TruncatedColourPng) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  const auto broken = sample_files(sequence, "rgb")[1];
  truncate_file(broken, 0.5);
  expect_clean_error(replay(sequence, out), 1, broken.string(), out);
}

TEST_F(SequenceRobustness, CorruptDepthPng) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  const auto broken = sample_files(sequence, "depth")[2];
  std::string bytes = read_text_file(broken);
  std::fill(bytes.begin() + static_cast<std::ptrdiff_t>(bytes.size() / 3),
            bytes.begin() + static_cast<std::ptrdiff_t>(bytes.size() / 2), '\x5a');  // image data, header intact
  write_file_atomically(broken, bytes);
  expect_clean_error(replay(sequence, out), 1, broken.string(), out);
}

// A colour PNG of a few kilobytes whose header claims 30 000 x 30 000 pixels is refused from its
// header, naming the file, its claimed size and the limit, with memory bounded.
TEST_F(SequenceRobustness, ColourPngClaiming30000x30000Pixels) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  const auto huge = sample_files(sequence, "rgb")[1];
  claim_png_size(huge, 30000, 30000);
  const auto run = replay(sequence, out);
  expect_clean_error(run, 1, huge.string() + ": a 30000x30000 PNG image, over the limit of", out);
  expect_bounded_memory(run);
}

TEST_F(SequenceRobustness, NotAPngAtAll) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  const auto broken = sample_files(sequence, "depth")[0];
  write_file_atomically(broken, std::string_view("this is not an image\n"));
  expect_clean_error(replay(sequence, out), 1, broken.string(), out);
}

TEST_F(SequenceRobustness, EightBitDepthPng) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  const auto depth = sample_files(sequence, "depth")[1];
  write_mask(depth, Mask(640, 480, 200));
  const auto run = replay(sequence, out);
  expect_clean_error(run, 1, depth.string(), out);
  EXPECT_NE(run.err.find("8-bit"), std::string::npos) << run.err;
}

TEST_F(SequenceRobustness, WrongSizeColourFrame) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  write_color(sample_files(sequence, "rgb")[2], ColorImage(320, 240, Rgb8{90, 90, 90}));
  const auto run = replay(sequence, out);
  // The pair is named by its depth file, with both sizes.
  expect_clean_error(run, 1, sample_files(sequence, "depth")[2].string(), out);
  EXPECT_NE(run.err.find("320x240"), std::string::npos) << run.err;
}

TEST_F(SequenceRobustness, MalformedRgbTxt) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  write_file_atomically(sequence / "rgb.txt", read_text_file(sequence / "rgb.txt") + "1305031229.7 rgb/a.png extra\n");
  expect_clean_error(replay(sequence, out), 1, (sequence / "rgb.txt").string() + ":8", out);
}

TEST_F(SequenceRobustness, MalformedGroundtruthTxt) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  std::string text = read_text_file(sequence / "groundtruth.txt");
  text.replace(text.find("1.3042"), 6, "1.3O42");  // letter O for zero, line 4
  write_file_atomically(sequence / "groundtruth.txt", text);
  const auto run = replay(sequence, out);
  expect_clean_error(run, 1, (sequence / "groundtruth.txt").string() + ":4", out);
  EXPECT_NE(run.err.find("1.3O42"), std::string::npos) << run.err;
}

TEST_F(SequenceRobustness, UnsortedTimestamps) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  std::string text = read_text_file(sequence / "depth.txt");
  const auto second = text.find("1305031229.564442"), third = text.find("1305031229.596617");
  const std::string line_two = text.substr(second, third - second);
  text.erase(second, line_two.size());
  text.insert(text.find('\n', text.find("1305031229.596617")) + 1, line_two);  // lines 5 and 6 swapped
  write_file_atomically(sequence / "depth.txt", text);
  const auto run = replay(sequence, out);
  expect_clean_error(run, 1, (sequence / "depth.txt").string() + ":6", out);
  EXPECT_NE(run.err.find("not increasing"), std::string::npos) << run.err;
}


// A depth image without one valid pixel cannot be reconstructed: an error naming it (a frame
// that --skip-bad-frames skips with a warning).
TEST_F(SequenceRobustness, DepthAllZero) {
  const auto sequence = copy_of_sample(dir.path() / "seq");
  const auto zero = sample_files(sequence, "depth")[1];
  write_depth_png(zero, DepthMap(640, 480, 0.f), 5000.0);
  expect_clean_error(replay(sequence, out), 1, zero.string(), out);
  const auto skipped = replay(sequence, dir.path() / "skipped", {"--skip-bad-frames"});
  expect_clean_success(skipped, dir.path() / "skipped");
  EXPECT_EQ(count_lines(skipped.err), 1u) << skipped.err;
  EXPECT_NE(skipped.err.find("relight: warning: frame 1 skipped"), std::string::npos) << skipped.err;
}

// The same while rendering: frame 0 is composited, frame 1 stops the run; composite.mp4 must not
// be left half-written.
TEST_F(SequenceRobustness, DepthAllZeroWhileRendering) {
  const auto sequence = copy_of_synthetic(dir.path() / "seq");
  const auto zero = sample_files(sequence, "depth")[1];
  write_depth_png(zero, DepthMap(640, 480, 0.f), 5000.0);
  const auto run = run_relight({"replay", "--quiet", sequence.string(), "--object",
                                (kData / "models" / "glossy_pebble.gltf").string(), "--vpls", "8", "--out", out.string()});
  expect_clean_error(run, 1, zero.string(), out);
}

}  // namespace
}  // namespace relight::robustness
