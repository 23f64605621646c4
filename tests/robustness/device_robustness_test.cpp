// Robustness matrix, devices: no Vulkan driver at all (the CPU path, with one warning), relight's
// OpenNI2 device unplugged mid-stream, cut or empty .oni recordings.
#include <gtest/gtest.h>

#include "inputs.h"
#include "outcome_checks.h"

namespace relight::robustness {
namespace {

// 320x240 keeps the synthetic device fast (~45 ms a frame).
const std::string kDevice = "relight://synthetic?size=320x240";

TEST(DeviceRobustness, NoVulkanDriverRendersOnTheCpuWithOneWarning) {
  TempDir dir;
  const auto out = dir.path() / "out";
  BoundedRun run;
  run.arguments = {"replay", "--quiet", synthetic_sequence().string(), "--object",
                   (kData / "models" / "glossy_pebble.gltf").string(), "--vpls", "8", "--out", out.string()};
  // Older loaders read VK_ICD_FILENAMES, newer ones VK_DRIVER_FILES: both point at nothing.
  const std::string nowhere = (dir.path() / "no_driver.json").string();
  run.environment = {{"VK_ICD_FILENAMES", nowhere}, {"VK_DRIVER_FILES", nowhere}};
  const auto outcome = run_relight(run);
  expect_clean_success(outcome, out);
  EXPECT_EQ(count_lines(outcome.err), 1u) << outcome.err;
  EXPECT_EQ(outcome.err.rfind("relight: warning: no usable Vulkan device, using the CPU path", 0), 0u) << outcome.err;
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000001_composite.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "composite.mp4"));
}

}  // namespace
}  // namespace relight::robustness
