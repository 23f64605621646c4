// The relight executable as users run it: exit codes, one-line errors, outputs.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "cli.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_dispatches_on_the_device;
using cli_test::expect_one_line_error;
using cli_test::relight;

const std::string kRelight = RELIGHT_BIN;
const std::filesystem::path kSample = std::filesystem::path(RELIGHT_TEST_DATA) / "tum_fr1_rpy";

std::size_t temporary_files_under(const std::filesystem::path& folder) {
  std::size_t count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) ++count;
  }
  return count;
}

TEST(Cli, HelpListsTheSubcommands) {
  const auto result = relight("--help");
  EXPECT_EQ(result.exit_code, 0);
  for (const char* command : {"replay", "graph", "synth"}) EXPECT_NE(result.out.find(command), std::string::npos) << command;
  EXPECT_EQ(relight("replay --help").exit_code, 0);
}

TEST(Cli, NoSubcommandOrUnknownFlagIsAUsageError) {
  EXPECT_EQ(relight("").exit_code, 2);
  EXPECT_EQ(relight("replay --no-such-flag").exit_code, 2);
}

// Geometry only (the main job's pebble: placement_cli_test.cpp).
TEST(Cli, ReplayOfTheEmbeddedSampleWritesFramesReportAndGraph) {
  test::TempDir dir;
  const auto result = relight("replay --quiet --no-object --out " + dir.path().string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "report.json"));
  EXPECT_EQ(report["frames"], 4);
  std::set<std::string> stages;
  for (const auto& stage : report["stages"]) {
    stages.insert(stage["stage"]);
    EXPECT_EQ(stage["wall_ms"].size(), 4u) << stage["stage"];
    EXPECT_GE(stage["median_ms"].get<double>(), 0.0);
    EXPECT_GE(stage["cpu_median_ms"].get<double>(), 0.0) << stage["stage"];
  }
  EXPECT_TRUE(stages.count("source"));
  EXPECT_TRUE(stages.count("frame_writer"));
  const ColorImage color = read_color(dir.path() / "frames" / "000003_color.png");
  EXPECT_EQ(color.width(), 640);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "frames" / "000003_depth.png"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "graph.dot"));
  EXPECT_EQ(temporary_files_under(dir.path()), 0u);

  // report.html: 4 frames x (colour, smoothed depth, normals) as inline JPEGs, every stage in the
  // timing table, and the frame graph drawn by Graphviz (a dependency of the test command).
  const std::string html = read_text_file(dir.path() / "report.html");
  std::size_t pictures = 0;
  for (auto at = html.find("src=\"data:image/jpeg;base64,/9j/"); at != std::string::npos;
       at = html.find("src=\"data:image/jpeg;base64,/9j/", at + 1)) {
    ++pictures;
  }
  EXPECT_EQ(pictures, 12u);
  for (const auto& stage : stages) EXPECT_NE(html.find("<td class=l>" + stage + "<"), std::string::npos) << stage;
  EXPECT_NE(html.find(">cores busy<"), std::string::npos);
  EXPECT_NE(html.find("<div class=graph><svg"), std::string::npos);
}

TEST(Cli, ReportListsTheGraphWhenGraphvizIsMissing) {
  test::TempDir dir;
  const auto result =
      test::run_command("PATH=/nonexistent " + std::string(RELIGHT_BIN) +
                        " replay --quiet --no-object --frames 1 --no-frames --out " + dir.path().string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string html = read_text_file(dir.path() / "report.html");
  EXPECT_NE(html.find("Graphviz (dot) is not installed"), std::string::npos);
  EXPECT_NE(html.find("<li>source"), std::string::npos);
  EXPECT_EQ(html.find("<div class=graph>"), std::string::npos);
}

TEST(Cli, FrameRangeLimitsTheRun) {
  test::TempDir dir;
  ASSERT_EQ(relight("replay --quiet --no-object --frames 1:3 --out " + dir.path().string()).exit_code, 0);
  EXPECT_EQ(nlohmann::json::parse(read_text_file(dir.path() / "report.json"))["frames"], 2);
}

TEST(Cli, LoopPlaysTheRangeAgainAndReportsPeakMemory) {
  test::TempDir dir;
  ASSERT_EQ(relight("replay --quiet --no-object --no-frames --frames 1:3 --loop 3 --out " + dir.path().string()).exit_code, 0);
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "report.json"));
  EXPECT_EQ(report["frames"], 6);
  EXPECT_NE(report["sequence"].get<std::string>().find("played 3 times"), std::string::npos);
  EXPECT_GT(report["peak_rss_mb"].get<double>(), 1.0);
  // stdin, stdout and stderr at least; the outputs are closed by the end of the run.
  EXPECT_GE(report["open_file_descriptors"].get<int>(), 3);
  EXPECT_LT(report["open_file_descriptors"].get<int>(), 64);
  expect_one_line_error(relight("replay --quiet --loop 0 --out " + dir.path().string()), 2);
  // A value outside an option's choices is a usage error, like every other bad choice.
  expect_one_line_error(relight("replay --intrinsics fr9 --out " + dir.path().string()), 2);
}

TEST(Cli, BadInputGivesOneLineAndExitCodeOne) {
  test::TempDir dir;
  expect_one_line_error(relight("replay /no/such/folder --out " + dir.path().string()), 1);
  expect_one_line_error(relight("replay --frames 3:1 --out " + dir.path().string()), 1);
  expect_one_line_error(relight("replay --frames x --out " + dir.path().string()), 1);
}

TEST(Cli, CorruptFrameMidSequenceFailsCleanlyWithoutPartialFiles) {
  test::TempDir dir;
  const auto sequence = dir.path() / "seq";
  std::filesystem::copy(kSample, sequence, std::filesystem::copy_options::recursive);
  write_file_atomically(sequence / "depth" / "1305031229.596617.png", std::string_view("\x89PNG\r\n\x1a\nbroken"));
  const auto out = dir.path() / "out";
  const auto result = relight("replay " + sequence.string() + " --quiet --out " + out.string());
  expect_one_line_error(result, 1);
  EXPECT_NE(result.err.find("1305031229.596617.png"), std::string::npos) << result.err;
  EXPECT_EQ(temporary_files_under(out), 0u);
  EXPECT_FALSE(std::filesystem::exists(out / "report.json"));
}

// The pictures of the inner buffers (depth, smoothed depth, normals, the BRDF mosaic) are made
// and written for the frames report.html shows (8 frames: 0, 2, 4 and 7), the camera image and
// the composites for every frame; --previews every writes all of them for every frame.
TEST(Cli, ReplayWritesTheInnerBuffersPicturesForTheFramesTheReportShows) {
  test::TempDir dir;
  const auto shown = dir.path() / "shown", every = dir.path() / "every";
  const auto result = relight("replay --quiet --loop 2 --no-video --out " + shown.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto written = [](const std::filesystem::path& out, int frame, const std::string& buffer) {
    char name[32];
    std::snprintf(name, sizeof name, "%06d_", frame);
    return std::filesystem::exists(out / "frames" / (name + buffer + ".png"));
  };
  for (int frame = 0; frame < 8; ++frame) {
    const bool on_the_report = frame == 0 || frame == 2 || frame == 4 || frame == 7;
    for (const char* buffer : {"color", "composite_mapped"})
      EXPECT_TRUE(written(shown, frame, buffer)) << frame << " " << buffer;
    // The composite before colour mapping is an intermediate when the mapped one is the picture.
    for (const char* buffer : {"depth", "depth_smoothed", "normals", "brdf_preview", "composite"})
      EXPECT_EQ(written(shown, frame, buffer), on_the_report) << frame << " " << buffer;
  }
  const auto report = nlohmann::json::parse(read_text_file(shown / "report.json"));
  EXPECT_EQ(report["frames"], 8);

  ASSERT_EQ(relight("replay --quiet --loop 2 --no-video --previews every --out " + every.string()).exit_code, 0);
  for (int frame = 0; frame < 8; ++frame)
    for (const char* buffer : {"color", "depth", "depth_smoothed", "normals", "brdf_preview", "composite"})
      EXPECT_TRUE(written(every, frame, buffer)) << frame << " " << buffer;
  expect_one_line_error(relight("replay --previews sometimes --out " + dir.path().string()), 2);
}

// A recording without a light probe (every TUM sequence) is lit by the light estimated from its
// own frames (issue: `--lights estimate` is the default without a probe), and the run says why.
TEST(Cli, ReplayOfARecordingWithoutAProbeEstimatesItsLights) {
  test::TempDir dir;
  const std::string sample = std::string(RELIGHT_TEST_DATA) + "/tum_fr1_rpy";
  const auto result = relight("replay " + sample + " --frames 0:2 --vpls 8 --no-video --object " + RELIGHT_TEST_DATA +
                              "/models/glossy_pebble.gltf --place-on-plane --out " + dir.path().string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find(sample + " has no light probe: the real lights are estimated from the frames"),
            std::string::npos)
      << result.err;
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "report.json"));
  ASSERT_TRUE(report.contains("light_estimate")) << report.dump();
  EXPECT_EQ(report["light_estimate"]["chosen"], sample + " has no light probe");
  EXPECT_EQ(report["light_estimate"]["evidence"], "shadows") << report["light_estimate"].dump();
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "frames" / "000001_composite_mapped.png"));
}

TEST(Cli, VulkanAndCpuBackendsWriteTheSameSmoothedDepth) {
  test::TempDir dir;
  const auto cpu = dir.path() / "cpu", vulkan = dir.path() / "vulkan";
  ASSERT_EQ(relight("replay --quiet --no-object --frames 0:2 --backend cpu --out " + cpu.string()).exit_code, 0);
  const auto result = relight("replay --quiet --no-object --frames 0:2 --backend vulkan --out " + vulkan.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* file : {"000000_depth_smoothed.png", "000001_depth_smoothed.png"}) {
    EXPECT_EQ(read_text_file(cpu / "frames" / file), read_text_file(vulkan / "frames" / file)) << file;
  }
  const auto report = nlohmann::json::parse(read_text_file(vulkan / "report.json"));
  EXPECT_EQ(expect_dispatches_on_the_device(report, "depth_box_filter").value("buffers", ""), "device");
  // Outside the option's choices: a usage error, as for every option with a fixed set of values.
  expect_one_line_error(relight("replay --backend quantum --out " + dir.path().string()), 2);
}

// The geometry stages follow the per-pixel backend: with --backend vulkan both methods (and
// both kinds of method-2 normals) report device time for each of their stages and work on the
// graph's device buffers.
TEST(Cli, VulkanBackendRunsBothGeometryMethodsOnTheDevice) {
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::vector<std::string>>> runs = {
      {"--geometry method1", {"normals_raw_depth"}},
      {"--geometry method2", {"depth_warp_merge", "normals_filtered_depth"}},
      {"--geometry method2 --method2-normals plain", {"depth_warp_merge", "normals_from_positions"}}};
  for (std::size_t run = 0; run < runs.size(); ++run) {
    const auto& [arguments, stages] = runs[run];
    const auto out = dir.path() / std::to_string(run);
    const auto result =
        relight("replay --quiet --no-object --no-frames --frames 0:2 --backend vulkan " + arguments + " --out " + out.string());
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
    for (const std::string& name : stages) {
      // The graph hands them device buffers: no stage transfers on its own.
      EXPECT_EQ(expect_dispatches_on_the_device(report, name).value("buffers", ""), "device") << arguments;
    }
  }
}

TEST(Cli, WithoutAnyVulkanDeviceReplayFallsBackToTheCpuAndSaysSoOnce) {
  test::TempDir dir;
  const std::string no_driver = "VK_ICD_FILENAMES=" + (dir.path() / "none.json").string() + " ";
  const auto result =
      test::run_command(no_driver + kRelight + " replay --quiet --no-object --frames 0:1 --out " + dir.path().string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  std::size_t notes = 0;
  for (std::size_t at = 0; (at = result.err.find("no usable Vulkan device", at)) != std::string::npos; ++at) ++notes;
  EXPECT_EQ(notes, 1u) << result.err;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "frames" / "000000_depth_smoothed.png"));
  const auto forced = test::run_command(no_driver + kRelight + " replay --backend vulkan --out " + dir.path().string());
  EXPECT_EQ(forced.exit_code, 1);
  EXPECT_NE(forced.err.find("relight: error: the Vulkan backend was forced"), std::string::npos) << forced.err;
}

TEST(Cli, JsonConfigSuppliesOptionsAndTheCommandLineWins) {
  test::TempDir dir;
  const auto config = dir.path() / "cfg.json";
  const auto out = dir.path() / "out";
  write_file_atomically(config, "{\"frames\": \"0:3\", \"quiet\": true, \"no-object\": true, \"out\": \"" + out.string() + "\"}");
  ASSERT_EQ(relight("replay --config " + config.string()).exit_code, 0);
  EXPECT_EQ(nlohmann::json::parse(read_text_file(out / "report.json"))["frames"], 3);
  ASSERT_EQ(relight("replay --config " + config.string() + " --frames 0:1").exit_code, 0);
  EXPECT_EQ(nlohmann::json::parse(read_text_file(out / "report.json"))["frames"], 1);
}

// A structural check of the DOT text: one digraph, every edge joins declared nodes.
TEST(Cli, GraphDotIsAValidGraph) {
  const auto result = relight("graph --dot");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out.rfind("digraph relight {", 0), 0u);
  std::set<std::string> nodes;
  const std::regex node(R"re(^\s*("[^"]+")\s*\[)re"), edge(R"re(^\s*("[^"]+")\s*->\s*("[^"]+"))re");
  std::istringstream lines(result.out);
  int edges = 0;
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, edge)) {
      ++edges;
      EXPECT_TRUE(nodes.count(m[1]) && nodes.count(m[2])) << line;
    } else if (std::regex_search(line, m, node)) {
      nodes.insert(m[1]);
    }
  }
  EXPECT_GE(edges, 3);
  EXPECT_EQ(std::count(result.out.begin(), result.out.end(), '"') % 2, 0);
  const auto order = relight("graph");
  EXPECT_EQ(order.out.rfind("source\n", 0), 0u) << order.out;
}

// `relight graph` takes replay's rendering options, so it shows the graph of any content: here
// without colour mapping the mapping stages are gone, and without content no renderer runs.
TEST(Cli, GraphFollowsTheRenderingOptions) {
  const auto mapped = relight("graph");
  ASSERT_EQ(mapped.exit_code, 0) << mapped.err;
  EXPECT_NE(mapped.out.find("\ndir\n"), std::string::npos) << mapped.out;
  EXPECT_NE(mapped.out.find("\nmapped_composite\n"), std::string::npos) << mapped.out;
  const auto unmapped = relight("graph --colormap none");
  ASSERT_EQ(unmapped.exit_code, 0) << unmapped.err;
  EXPECT_NE(unmapped.out.find("\ndir\n"), std::string::npos) << unmapped.out;
  EXPECT_EQ(unmapped.out.find("mapped_composite"), std::string::npos) << unmapped.out;
  const auto geometry = relight("graph --no-object");
  ASSERT_EQ(geometry.exit_code, 0) << geometry.err;
  EXPECT_EQ(geometry.out.find("\ndir\n"), std::string::npos) << geometry.out;
  EXPECT_NE(relight("graph --view").exit_code, 0);  // a window is replay's and live's, not graph's
}

TEST(Cli, SynthWritesASequenceThatReplayReads) {
  test::TempDir dir;
  const auto sequence = dir.path() / "synth";
  const auto made = relight("synth --quiet --frames 2 --trajectory static --out " + sequence.string());
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const auto scene = nlohmann::json::parse(read_text_file(sequence / "scene.json"));
  EXPECT_DOUBLE_EQ(scene["intrinsics"]["fx"].get<double>(), 525.0);
  const auto out = dir.path() / "out";
  const auto replayed = relight("replay " + sequence.string() + " --quiet --out " + out.string());
  ASSERT_EQ(replayed.exit_code, 0) << replayed.err;
  const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
  EXPECT_EQ(report["frames"], 2);
  // The synthetic scene.json describes its AprilTag, so the marker pose runs and is compared with
  // the exact poses of the sequence (Kinect-noisy depth, aliased colour: a few centimetres at most).
  ASSERT_TRUE(report.contains("marker_pose")) << report.dump();
  EXPECT_EQ(report["marker_pose"]["frames_with_marker_pose"], 2);
  EXPECT_LT(report["marker_pose"]["max_error_cm"].get<double>(), 3.0);
  EXPECT_LT(report["marker_pose"]["max_error_deg"].get<double>(), 2.0);
  const std::string trajectory = read_text_file(out / "marker_trajectory.txt");
  EXPECT_EQ(std::count(trajectory.begin(), trajectory.end(), '\n'), 4);  // 2 comment lines + 2 poses
  const auto without = dir.path() / "without";
  ASSERT_EQ(relight("replay " + sequence.string() + " --markers none --quiet --out " + without.string()).exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(without / "marker_trajectory.txt"));
  expect_one_line_error(relight("replay " + sequence.string() + " --markers " + (dir.path() / "no.json").string() +
                                " --quiet --out " + without.string()),
                        1);
  EXPECT_EQ(relight("synth --out " + sequence.string() + " --trajectory loop").exit_code, 2);
  EXPECT_EQ(relight("synth --frames 3").exit_code, 2);  // --out is required
}

}  // namespace
}  // namespace relight::app
