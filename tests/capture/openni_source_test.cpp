// relight's OpenNI2 driver seen through the public OpenNI2 API (openni::OpenNI, Device,
// VideoStream) and through OpenNiSource: enumeration, stream properties, frames equal to synth's
// ground truth, timestamps, looping TUM folders, an unplugged device, bad URIs.
#include <gtest/gtest.h>

#include <OpenNI.h>

#include <chrono>
#include <cmath>

#include "relight/capture/depth_millimetres.h"
#include "relight/capture/openni_source.h"
#include "relight/capture/tum_sequence.h"
#include "relight/core/error.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/sequence.h"
#include "relight/synth/trajectory.h"

namespace relight::capture {
namespace {

const std::filesystem::path kSample = std::filesystem::path(RELIGHT_TEST_DATA) / "tum_fr1_rpy";

// Frame k of relight://synthetic (orbit, loop 540) has timestamp 1 s + k / 30 s.
std::int64_t synthetic_index(std::uint64_t timestamp_us) {
  return std::llround((static_cast<double>(timestamp_us) - 1e6) * 30.0 / 1e6);
}

// What the driver must send for frame k at width x height: synth's exact depth, rounded to mm.
std::vector<std::uint16_t> expected_depth_mm(std::int64_t k, int width, int height) {
  static const synth::Scene scene = synth::default_indoor_scene();
  static const auto poses = synth::make_trajectory(synth::Trajectory::Orbit, 540, 0, scene);
  synth::SynthOptions options;
  options.width = width;
  options.height = height;
  const auto rendered = synth::render_frame(scene, synth::synth_intrinsics(options), poses[static_cast<std::size_t>(k % 540)]);
  std::vector<std::uint16_t> mm(rendered.depth.size());
  for (std::size_t i = 0; i < mm.size(); ++i) mm[i] = depth_to_millimetres(rendered.depth.data()[i]);
  return mm;
}

std::vector<std::uint16_t> to_mm(const DepthMap& depth) {
  std::vector<std::uint16_t> mm(depth.size());
  for (std::size_t i = 0; i < mm.size(); ++i) mm[i] = depth_to_millimetres(depth.data()[i]);
  return mm;
}

// OpenNI::initialize/shutdown around a test that uses the C++ API directly.
struct OpenNiSession {
  OpenNiSession() { EXPECT_EQ(openni::OpenNI::initialize(), openni::STATUS_OK) << openni::OpenNI::getExtendedError(); }
  ~OpenNiSession() { openni::OpenNI::shutdown(); }
};

TEST(OpenNiDriver, OpenNiListsTheSyntheticDevice) {
  const auto devices = list_openni_devices();
  const bool found = std::any_of(devices.begin(), devices.end(), [](const auto& d) {
    return d.uri == "relight://synthetic" && d.vendor == "relight";
  });
  EXPECT_TRUE(found);
}

TEST(OpenNiDriver, StreamsReportModesAndPropertiesLikeADevice) {
  OpenNiSession session;
  openni::Device device;
  ASSERT_EQ(device.open("relight://synthetic"), openni::STATUS_OK) << openni::OpenNI::getExtendedError();
  const openni::SensorInfo* depth_info = device.getSensorInfo(openni::SENSOR_DEPTH);
  ASSERT_NE(depth_info, nullptr);
  ASSERT_NE(device.getSensorInfo(openni::SENSOR_COLOR), nullptr);
  const auto& modes = depth_info->getSupportedVideoModes();
  ASSERT_EQ(modes.getSize(), 2);
  EXPECT_EQ(modes[1].getResolutionX(), 320);
  EXPECT_TRUE(device.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR));
  EXPECT_EQ(device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR), openni::STATUS_OK);
  EXPECT_EQ(device.getImageRegistrationMode(), openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
  EXPECT_EQ(device.setDepthColorSyncEnabled(true), openni::STATUS_OK);

  openni::VideoStream depth;
  ASSERT_EQ(depth.create(device, openni::SENSOR_DEPTH), openni::STATUS_OK);
  const openni::VideoMode mode = depth.getVideoMode();
  EXPECT_EQ(mode.getResolutionX(), 640);
  EXPECT_EQ(mode.getResolutionY(), 480);
  EXPECT_EQ(mode.getFps(), 30);
  EXPECT_EQ(mode.getPixelFormat(), openni::PIXEL_FORMAT_DEPTH_1_MM);
  EXPECT_NEAR(depth.getHorizontalFieldOfView(), 2.0 * std::atan(320.0 / 525.0), 1e-6);
  EXPECT_NEAR(depth.getVerticalFieldOfView(), 2.0 * std::atan(240.0 / 525.0), 1e-6);
  EXPECT_EQ(depth.getMaxPixelValue(), 10000);
  int stride = 0;
  EXPECT_EQ(depth.getProperty(openni::STREAM_PROPERTY_STRIDE, &stride), openni::STATUS_OK);
  EXPECT_EQ(stride, 640 * 2);
  EXPECT_FALSE(depth.getMirroringEnabled());

  // Switch to 320x240, mirror and crop; the frame must be the mirrored crop of the full image.
  EXPECT_EQ(depth.setVideoMode(modes[1]), openni::STATUS_OK);
  EXPECT_EQ(depth.getVideoMode().getResolutionX(), 320);
  openni::VideoMode bad = modes[1];
  bad.setResolution(123, 45);
  EXPECT_NE(depth.setVideoMode(bad), openni::STATUS_OK);
  EXPECT_EQ(depth.setMirroringEnabled(true), openni::STATUS_OK);
  EXPECT_EQ(depth.setCropping(10, 20, 100, 50), openni::STATUS_OK);
  int x = 0, y = 0, w = 0, h = 0;
  EXPECT_TRUE(depth.getCropping(&x, &y, &w, &h));
  EXPECT_EQ(w, 100);
  ASSERT_EQ(depth.start(), openni::STATUS_OK);
  openni::VideoStream* streams[] = {&depth};
  int ready = -1;
  ASSERT_EQ(openni::OpenNI::waitForAnyStream(streams, 1, &ready, 5000), openni::STATUS_OK);
  openni::VideoFrameRef frame;
  ASSERT_EQ(depth.readFrame(&frame), openni::STATUS_OK);
  ASSERT_EQ(frame.getWidth(), 100);
  ASSERT_EQ(frame.getHeight(), 50);
  EXPECT_EQ(frame.getStrideInBytes(), 200);
  EXPECT_TRUE(frame.getCroppingEnabled());
  const auto full = expected_depth_mm(synthetic_index(frame.getTimestamp()), 320, 240);
  const auto* pixels = static_cast<const std::uint16_t*>(frame.getData());
  int mismatches = 0;
  for (int r = 0; r < 50; ++r) {
    for (int c = 0; c < 100; ++c) {
      mismatches += pixels[r * 100 + c] != full[static_cast<std::size_t>((20 + r) * 320 + (320 - 1 - (10 + c)))];
    }
  }
  EXPECT_EQ(mismatches, 0);
  depth.stop();
  depth.destroy();
  device.close();
}

TEST(OpenNiDriver, FramesEqualSynthGroundTruthAtTheDeviceFrameRate) {
  OpenNiOptions options;
  options.uri = "relight://synthetic?size=320x240";
  OpenNiSource source(options);
  EXPECT_FALSE(source.is_file());
  EXPECT_EQ(source.size_hint(), 0);
  EXPECT_NE(source.describe().find("relight://synthetic"), std::string::npos);
  std::vector<double> timestamps;
  for (int i = 0; i < 4; ++i) {
    auto frame = source.next();
    ASSERT_TRUE(frame);
    ASSERT_EQ(frame->depth.width(), 320);
    EXPECT_NEAR(frame->info.intrinsics.fx, 262.5, 1e-3);
    EXPECT_NEAR(frame->info.intrinsics.cx, 159.5, 1e-9);
    const std::int64_t k = synthetic_index(source.last_timestamp_us());
    EXPECT_EQ(to_mm(frame->depth), expected_depth_mm(k, 320, 240)) << "frame " << k;
    timestamps.push_back(frame->info.timestamp);
  }
  for (std::size_t i = 1; i < timestamps.size(); ++i) {
    const double step = timestamps[i] - timestamps[i - 1];
    // The reader may skip frames when it is slower than the device, never go back.
    EXPECT_GT(step, 0.0);
    const double periods = step * 30.0;
    EXPECT_NEAR(periods, std::round(periods), 1e-4) << step;
  }
  EXPECT_EQ(source.dropped(), std::llround((timestamps.back() - timestamps.front()) * 30.0) - 3);
}

TEST(OpenNiDriver, ShortLoopRunsAtTheFrameRateOnceRendered) {
  OpenNiOptions options;
  options.uri = "relight://synthetic?size=320x240&loop=2";
  OpenNiSource source(options);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(source.next());  // the first pass renders, the rest is cached
  std::vector<std::pair<std::int64_t, RgbdFrame>> frames;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 6; ++i) {
    auto frame = source.next();
    ASSERT_TRUE(frame);
    frames.emplace_back(synthetic_index(source.last_timestamp_us()), std::move(*frame));
  }
  // 6 frames at 30 fps take 0.2 s; rendering them would take ~0.3 s idle, ~1 s on busy cores.
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(600));
  EXPECT_EQ(frames.back().first - frames.front().first, 5);  // none dropped
  for (const auto& [k, frame] : frames) EXPECT_EQ(to_mm(frame.depth), expected_depth_mm(k % 2, 320, 240)) << k;
}

TEST(OpenNiDriver, ColourIsSynthsRenderedRadiance) {
  OpenNiOptions options;
  options.uri = "relight://synthetic?size=320x240&trajectory=static";
  OpenNiSource source(options);
  const auto frame = source.next();
  ASSERT_TRUE(frame);
  const synth::Scene scene = synth::default_indoor_scene();
  synth::SynthOptions synth_options;
  synth_options.width = 320;
  synth_options.height = 240;
  const auto pose = synth::make_trajectory(synth::Trajectory::Static, 1, 0, scene)[0];
  const ColorImage expected =
      synth::encode_color(synth::render_frame(scene, synth::synth_intrinsics(synth_options), pose).radiance);
  ASSERT_TRUE(frame->color.same_shape(expected));
  EXPECT_TRUE(std::equal(expected.data(), expected.data() + expected.size(), frame->color.data()));
}

TEST(OpenNiDriver, TumFolderLoopsWithIncreasingTimestamps) {
  const TumSequence sequence = TumSequence::open(kSample);
  OpenNiOptions options;
  options.uri = "relight://tum/" + std::filesystem::absolute(kSample).string();
  OpenNiSource source(options);
  std::vector<RgbdFrame> frames;
  // Read one pass and the first frame of the next; the device runs at the folder's pace (~30 fps)
  // and we read faster than that, so nothing is dropped.
  for (std::size_t i = 0; i <= sequence.size(); ++i) {
    auto frame = source.next();
    ASSERT_TRUE(frame);
    frames.push_back(std::move(*frame));
  }
  EXPECT_EQ(source.dropped(), 0);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const RgbdFrame expected = sequence.load(i % sequence.size());
    EXPECT_EQ(to_mm(frames[i].depth), to_mm(expected.depth)) << i;
    EXPECT_TRUE(std::equal(expected.color.data(), expected.color.data() + expected.color.size(), frames[i].color.data())) << i;
    if (i > 0) {
      EXPECT_GT(frames[i].info.timestamp, frames[i - 1].info.timestamp);
    }
    if (i < sequence.size()) {
      EXPECT_NEAR(frames[i].info.timestamp, sequence.frame(i).depth_timestamp, 1e-6);
    }
  }
}

TEST(OpenNiDriver, DisconnectIsAClearErrorAndNoHang) {
  OpenNiOptions options;
  options.uri = "relight://synthetic?size=320x240&disconnect_after=3";
  options.timeout = std::chrono::milliseconds(20000);  // the disconnect, not the timeout, must end it
  OpenNiSource source(options);
  const auto start = std::chrono::steady_clock::now();
  int frames = 0;
  try {
    while (source.next()) ++frames;
    FAIL() << "the stream ended without an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("disconnected"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("relight://synthetic"), std::string::npos) << e.what();
  }
  EXPECT_LE(frames, 3);
  EXPECT_GE(frames, 1);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

// Unplugged after 3 frames and plugged back 6 frame periods (0.2 s) later: the source waits,
// opens the device again and goes on at the device's frame 9, with its timestamps and frames.
TEST(OpenNiDriver, DeviceThatComesBackIsReopenedAndReadingGoesOn) {
  OpenNiOptions options;
  options.uri = "relight://synthetic?size=320x240&disconnect_after=3&reconnect_after=6";
  options.reconnect_timeout = std::chrono::milliseconds(10000);
  std::vector<std::string> notices;
  options.on_notice = [&notices](const std::string& line) { notices.push_back(line); };
  OpenNiSource source(options);
  std::vector<RgbdFrame> frames;
  while (frames.size() < 6) {
    auto frame = source.next();
    ASSERT_TRUE(frame) << "the stream ended after " << frames.size() << " frames";
    frames.push_back(std::move(*frame));
  }
  ASSERT_EQ(source.reconnects().size(), 1u);
  const DeviceReconnect& reconnect = source.reconnects().front();
  // The OpenNI2 core may drop the frame in flight when the device goes (DeviceUnpluggedDuringLive).
  ASSERT_GE(reconnect.after_frames, 2);
  ASSERT_LE(reconnect.after_frames, 3);
  EXPECT_GE(reconnect.seconds_away, 0.15);  // 0.2 s less the delivery delay of the last frame
  EXPECT_LT(reconnect.seconds_away, 5.0);
  ASSERT_EQ(notices.size(), 2u);
  EXPECT_NE(notices[0].find("disconnected after " + std::to_string(reconnect.after_frames) + " frame"),
            std::string::npos)
      << notices[0];
  EXPECT_NE(notices[0].find("; waiting up to 10.0 s"), std::string::npos) << notices[0];
  EXPECT_NE(notices[1].find("is back after"), std::string::npos) << notices[1];
  const auto after = static_cast<std::size_t>(reconnect.after_frames);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::int64_t k = synthetic_index(static_cast<std::uint64_t>(std::llround(frames[i].info.timestamp * 1e6)));
    EXPECT_EQ(k, i < after ? static_cast<std::int64_t>(i) : 9 + static_cast<std::int64_t>(i - after)) << i;
    EXPECT_EQ(frames[i].info.index, static_cast<std::int64_t>(i));
    EXPECT_EQ(to_mm(frames[i].depth), expected_depth_mm(k, 320, 240)) << i;
  }
  EXPECT_EQ(source.dropped(), 0);  // the time away is not dropped frames
}

TEST(OpenNiDriver, DeviceThatStaysAwayFailsAfterTheReconnectTimeout) {
  OpenNiOptions options;
  options.uri = "relight://synthetic?size=320x240&disconnect_after=2&reconnect_after=3000";  // back after 100 s
  options.reconnect_timeout = std::chrono::milliseconds(500);
  OpenNiSource source(options);
  const auto start = std::chrono::steady_clock::now();
  try {
    while (source.next()) {
    }
    FAIL() << "the stream ended without an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did not come back within 0.5 s"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_TRUE(source.reconnects().empty());
}

// Ctrl-C while waiting: the stream ends as at the end of a recording, no error.
TEST(OpenNiDriver, WaitForADeviceStopsWhenAsked) {
  OpenNiOptions options;
  options.uri = "relight://synthetic?size=320x240&disconnect_after=2&reconnect_after=3000";
  options.reconnect_timeout = std::chrono::milliseconds(60000);
  bool waiting = false;
  options.on_notice = [&waiting](const std::string&) { waiting = true; };
  const auto start = std::chrono::steady_clock::now();
  options.stop_waiting = [&] {
    return waiting && std::chrono::steady_clock::now() - start > std::chrono::milliseconds(300);
  };
  OpenNiSource source(options);
  int frames = 0;
  while (source.next()) ++frames;
  EXPECT_TRUE(waiting);
  EXPECT_GE(frames, 1);
  EXPECT_LE(frames, 2);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
}

TEST(OpenNiDriver, BadUrisAreClearErrors) {
  for (const std::string uri : {"relight://nothing", "relight://synthetic?fps=0", "relight://synthetic?colour=red",
                                "relight://tum//no/such/folder", "relight://synthetic?reconnect_after=5"}) {
    OpenNiOptions options;
    options.uri = uri;
    try {
      OpenNiSource source(options);
      ADD_FAILURE() << uri << " opened";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(uri), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace relight::capture
