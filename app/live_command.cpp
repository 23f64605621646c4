// `relight devices`, `relight live` and `relight record`: OpenNI2 devices (a Kinect-class camera,
// or relight's own virtual device relight://synthetic | relight://tum/<folder>).
//
// live runs the replay frame graph (build_replay_pipeline) on a device; record writes what a
// device sends to a .oni file (openni::Recorder) or a TUM folder. Both stop after --frames N,
// on Ctrl-C (outputs finalised, device closed, exit 0) or when the device goes away (outputs
// finalised, then a one-line error, exit 1); live with --reconnect-timeout S first waits up to
// S seconds for the device to be plugged back and goes on (report.json lists the reconnects).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "camera_trajectory_stage.h"
#include "commands.h"
#include "device_loss.h"
#include "device_memory_watch.h"
#include "interrupt.h"
#include "live_view.h"
#include "option_values.h"
#include "relight/capture/openni_source.h"
#include "relight/capture/tum_writer.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "replay.h"
#include "report.h"
#include "view_stage.h"

namespace relight::app {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// "live: 120 frames, 29.8 fps, 0 dropped" on one terminal line, redrawn at most every 0.5 s.
class LiveStatus {
 public:
  LiveStatus(std::string label, bool quiet) : label_(std::move(label)), enabled_(!quiet && isatty(STDERR_FILENO)) {}
  /// `pose`: the last frame's camera pose, shown as the tracking state (tracking, or lost and why).
  void update(std::int64_t frames, std::int64_t dropped, const capture::CameraPose* pose = nullptr) {
    if (!enabled_ || Clock::now() - last_ < std::chrono::milliseconds(500)) return;
    last_ = Clock::now();
    const double elapsed = seconds_since(start_);
    const std::string tracking = !pose                  ? ""
                                 : pose->failure.empty() ? std::string(", tracking (") + to_string(pose->source) + ")"
                                                         : ", LOST: " + pose->failure;
    std::fprintf(stderr, "\r%s: %lld frames, %.1f fps, %lld dropped%s   ", label_.c_str(),
                 static_cast<long long>(frames), elapsed > 0 ? static_cast<double>(frames) / elapsed : 0.0,
                 static_cast<long long>(dropped), tracking.c_str());
    drawn_ = true;
  }
  void finish() {
    if (drawn_) std::fputc('\n', stderr);
    drawn_ = false;
  }
  /// Counts the frame rate from now (the device and the pipeline are set up).
  void restart() { start_ = Clock::now(); }

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_{};
};

// Ends the stream after `limit` frames (0: no limit) or on Ctrl-C, as the end of a recording would,
// so that the frame graph finishes normally.
class StoppableSource final : public capture::FrameSource {
 public:
  StoppableSource(std::unique_ptr<capture::OpenNiSource> source, std::int64_t limit)
      : source_(std::move(source)), limit_(limit) {}
  std::optional<RgbdFrame> next() override {
    if (InterruptGuard::interrupted() || (limit_ > 0 && frames_ >= limit_) || (stop_ && stop_())) return std::nullopt;
    auto frame = source_->next();
    if (frame) ++frames_;
    return frame;
  }
  std::int64_t size_hint() const override { return limit_; }
  std::string describe() const override { return source_->describe(); }
  [[nodiscard]] const capture::OpenNiSource& device() const { return *source_; }
  /// Also ends the stream when `stop` says so (the view's quit key).
  void stop_when(std::function<bool()> stop) { stop_ = std::move(stop); }

 private:
  std::unique_ptr<capture::OpenNiSource> source_;
  std::function<bool()> stop_;
  std::int64_t limit_;
  std::int64_t frames_ = 0;
};

struct LiveOptions {
  std::string device;  ///< OpenNI2 URI; empty = first device
  std::int64_t frames = 0;
  double reconnect_timeout_s = 0.0;  ///< how long to wait for an unplugged device; 0 = fail at once
  ReplayOptions replay;
};

int run_devices() {
  const auto devices = capture::list_openni_devices();
  if (devices.empty()) std::cerr << "relight devices: OpenNI2 sees no device\n";
  for (const auto& device : devices) std::cout << device.uri << "\t" << device.vendor << "\t" << device.name << "\n";
  return 0;
}

int run_live(const LiveOptions& options) {
  InterruptGuard interrupt;
  const bool quiet = options.replay.quiet;
  LiveStatus status("live", quiet);
  capture::OpenNiOptions device_options;
  device_options.uri = options.device;
  device_options.reconnect_timeout = std::chrono::milliseconds(std::llround(options.reconnect_timeout_s * 1000.0));
  device_options.stop_waiting = [] { return InterruptGuard::interrupted(); };
  device_options.on_notice = [&status, quiet](const std::string& line) {
    if (quiet) return;  // the report lists the reconnects
    status.finish();
    std::cerr << "relight live: " << line << "\n";
  };
  auto device = std::make_unique<capture::OpenNiSource>(device_options);
  if (device->is_file()) throw Error(options.device + " is a recording: use relight replay for .oni files");
  const std::filesystem::path device_scene = device->scene_folder();
  auto source = std::make_unique<StoppableSource>(std::move(device), options.frames);
  StoppableSource& stoppable = *source;
  const std::string description = source->describe();
  std::error_code ec;
  std::filesystem::create_directories(options.replay.out, ec);
  if (ec) throw Error("cannot create output folder " + options.replay.out.string() + ": " + ec.message());

  ReplayOptions replay = options.replay;
  replay.live_device = options.device.empty() ? "the first OpenNI2 device" : options.device;
  replay.device_scene = device_scene;
  ReplayPipeline pipeline = build_replay_pipeline(std::move(source), replay);
  if (pipeline.view) {
    LiveView& view = *pipeline.view;
    stoppable.stop_when([&view] { return view.quit_requested(); });
    pipeline.view_stage->count_dropped([&stoppable] { return stoppable.device().dropped(); });
  }
  FrameGraph& graph = *pipeline.graph;
  graph.compile();
  write_file_atomically(options.replay.out / "graph.dot", graph.to_dot());
  if (!quiet) std::cerr << "relight live: " << description << "; " << pipeline.compute << "; Ctrl-C stops\n";

  status.restart();
  const auto start = Clock::now();
  std::string failure;
  DeviceLossHook device_loss(pipeline.vulkan.get());
  DeviceMemoryWatch device_memory(pipeline.vulkan.get());
  try {
    while (true) {
      device_loss.before_frame(graph.frames_run());
      if (!graph.run_frame()) break;
      device_memory.after_frame(graph.frames_run());
      status.update(graph.frames_run(), stoppable.device().dropped(), pipeline.trajectory->last());
    }
  } catch (const Error& e) {
    // e.g. the device was unplugged or the GPU lost: keep what was processed, then report it
    failure = device_loss_message(e, graph.frames_run()).value_or(e.what());
  }
  status.finish();
  graph.finish();
  const double seconds = seconds_since(start);
  const std::int64_t dropped = stoppable.device().dropped();

  auto report = timing_report(graph, seconds);
  report["source"] = description;
  report["compute"] = pipeline.compute;
  report["dropped_frames"] = dropped;
  device_memory.add_to(report, graph.frames_run());
  const auto& reconnects = stoppable.device().reconnects();
  report["reconnects"] = nlohmann::json::array();
  for (const capture::DeviceReconnect& reconnect : reconnects) {
    report["reconnects"].push_back(
        {{"after_frames", reconnect.after_frames}, {"seconds_away", reconnect.seconds_away}});
  }
  const bool quit_from_view = pipeline.view && pipeline.view->quit_requested();
  report["stopped_by"] = !failure.empty()                ? "error: " + failure
                         : InterruptGuard::interrupted() ? "interrupt"
                         : quit_from_view                ? "view"
                                                         : "end";
  add_pipeline_summaries(report, pipeline, replay);
  write_reports(options.replay.out, "relight live: " + description, graph, report, pipeline.report);
  if (!quiet) {
    std::cerr << "relight live: " << graph.frames_run() << " frames in " << seconds << " s ("
              << (seconds > 0 ? static_cast<double>(graph.frames_run()) / seconds : 0.0) << " fps), " << dropped
              << " dropped"
              << (reconnects.empty() ? ""
                                     : ", device back " + std::to_string(reconnects.size()) +
                                           (reconnects.size() == 1 ? " time" : " times") + " after an unplug")
              << (InterruptGuard::interrupted() ? ", interrupted" : "") << "; results in "
              << options.replay.out.string() << "\n";
  }
  if (!failure.empty()) throw Error(failure);
  return 0;
}

struct RecordOptions {
  std::string device;
  std::int64_t frames = 0;
  std::filesystem::path out;
  bool quiet = false;
};

// A .oni is written under a temporary name and renamed once it is complete and checked, so a
// failed run never leaves a half-written recording under the requested name.
std::filesystem::path temporary_oni(const std::filesystem::path& out) {
  return out.parent_path() / (out.stem().string() + ".tmp-" + std::to_string(getpid()) + ".oni");
}

// "; the disk ... is full" when the file system holding `file` has less room left than one more
// 640x480 frame pair would take, else "".
std::string full_disk_cause(const std::filesystem::path& file) {
  constexpr std::uintmax_t kFramePairBytes = std::uintmax_t{640} * 480 * 5;  // 16-bit depth + RGB
  std::error_code ec;
  const std::filesystem::space_info space =
      std::filesystem::space(file.parent_path().empty() ? "." : file.parent_path(), ec);
  if (ec || space.available >= kFramePairBytes) return "";
  return "; the disk holding it is full (" + std::to_string(space.available) + " bytes free)";
}

// Every frame read after the recorder started must be in the file, at its device time. Played
// back, the file's timestamps count from its first frame, which may be one frame older than the
// first we read (it can come in while the recorder starts): try both alignments.
std::string check_recording(const capture::OniRecordingSummary& summary,
                            const std::vector<std::uint64_t>& delivered_us) {
  if (summary.depth_frames != summary.color_frames) {
    return "the recording holds " + std::to_string(summary.depth_frames) + " depth but " +
           std::to_string(summary.color_frames) + " colour frames";
  }
  if (delivered_us.empty()) return "";
  const auto& recorded = summary.depth_timestamps_us;
  if (recorded.empty())
    return "none of the " + std::to_string(delivered_us.size()) + " frames delivered is in the recording";
  std::string first_missing;
  for (std::size_t first = 0; first < std::min<std::size_t>(2, recorded.size()); ++first) {
    const std::uint64_t offset = delivered_us.front() - recorded[first];
    const auto missing = std::find_if(delivered_us.begin(), delivered_us.end(), [&](std::uint64_t t) {
      return !std::binary_search(recorded.begin(), recorded.end(), t - offset);
    });
    if (missing == delivered_us.end()) return "";
    if (first_missing.empty()) first_missing = std::to_string(missing - delivered_us.begin());
  }
  return "frame " + first_missing + " of the " + std::to_string(delivered_us.size()) +
         " delivered is missing from the recording (" + std::to_string(recorded.size()) + " frames)";
}

std::string camera_json(const PinholeIntrinsics& k, const std::string& source) {
  const nlohmann::ordered_json json = {
      {"generator", "relight record"},
      {"source", source},
      {"intrinsics", {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}, {"width", k.width}, {"height", k.height}}},
      {"depth_scale", 5000.0}};
  return json.dump(2) + "\n";
}

int run_record(const RecordOptions& options) {
  InterruptGuard interrupt;
  const bool to_oni = options.out.extension() == ".oni";
  capture::OpenNiOptions device_options;
  device_options.uri = options.device;
  capture::OpenNiSource source(device_options);
  if (to_oni && source.is_file()) throw Error("recording a .oni file into a .oni file: copy the file instead");

  std::optional<capture::TumWriter> tum;
  const std::filesystem::path temporary = to_oni ? temporary_oni(options.out) : std::filesystem::path();
  if (to_oni) {
    if (!options.out.parent_path().empty()) std::filesystem::create_directories(options.out.parent_path());
    // The streams run already (Recorder::attach needs started streams), so a frame that came in
    // before the recorder started may be read below without being in the file: the check allows it.
    source.start_recording(temporary);
  } else {
    tum.emplace(options.out);
  }
  if (!options.quiet) std::cerr << "relight record: " << source.describe() << " -> " << options.out.string() << "; Ctrl-C stops\n";

  LiveStatus status("record", options.quiet);
  const auto start = Clock::now();
  std::int64_t frames = 0;
  std::vector<std::uint64_t> delivered_us;  // device timestamps of the frames read
  std::optional<PinholeIntrinsics> intrinsics;
  std::string failure;
  try {
    while (!InterruptGuard::interrupted() && (options.frames == 0 || frames < options.frames)) {
      auto frame = source.next();
      if (!frame) break;  // end of a .oni being converted
      intrinsics = frame->info.intrinsics;
      delivered_us.push_back(source.last_timestamp_us());
      if (tum) tum->add(frame->info.timestamp, frame->color, frame->depth, frame->info.camera_to_world);
      ++frames;
      status.update(frames, source.dropped());
    }
  } catch (const Error& e) {
    failure = e.what();
  }
  status.finish();
  const double seconds = seconds_since(start);
  std::string held;
  if (to_oni) {
    source.stop_recording();
    // OpenNI2's recorder reports no write error (a full disk truncates the file silently), so the
    // file is read back; a file that fails the check is removed and the likely cause named.
    capture::OniRecordingSummary summary;
    std::string lost;
    try {
      summary = capture::inspect_oni(temporary);
      lost = check_recording(summary, delivered_us);
    } catch (const Error& e) {
      lost = e.what();
    }
    if (!lost.empty()) {
      const std::string cause = full_disk_cause(temporary);  // before the removal frees its space
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw Error(options.out.string() + ": " + lost + cause);
    }
    std::filesystem::rename(temporary, options.out);
    held = "; the file holds " + std::to_string(summary.depth_frames) + " depth and " +
           std::to_string(summary.color_frames) + " colour frames";
  } else {
    tum->finish();
    // The folder's camera, for TumSequence (as `relight synth` writes it).
    if (intrinsics) write_file_atomically(options.out / "scene.json", camera_json(*intrinsics, source.describe()));
  }
  if (!options.quiet) {
    std::cerr << "relight record: " << frames << " frames in " << seconds << " s, " << source.dropped()
              << " dropped by the reader" << held << (InterruptGuard::interrupted() ? ", interrupted" : "") << " -> "
              << options.out.string() << "\n";
  }
  if (!failure.empty()) throw Error(failure);
  return 0;
}

void add_live_compute_options(CLI::App& command, ReplayOptions& options) {
  add_choice_option(command, "--backend", options.backend, vk::kBackendPolicyNames, "As in replay");
  command.add_flag_callback(
      "--cpu", [&options] { options.backend = vk::BackendPolicy::ForceCpu; }, "Same as --backend cpu");
  command.add_option("--vk-device", options.device, "Vulkan device (replay's --device)");
  add_choice_option(command, "--geometry", options.geometry, kGeometryMethodNames, "Normal estimation (as in replay)");
  add_method2_normals_option(command, options);
}

}  // namespace

void register_live(CLI::App& app, Runners& runners) {
  CLI::App* devices = app.add_subcommand("devices", "List the RGB-D devices OpenNI2 sees (URI, vendor, name)");
  runners[devices] = [] { return run_devices(); };

  auto live_options = std::make_shared<LiveOptions>();
  live_options->replay.out.clear();
  CLI::App* live = app.add_subcommand("live", "Run the pipeline (as replay) on a live OpenNI2 device");
  live->add_option("--device", live_options->device,
                   "OpenNI2 device URI (relight devices lists them; relight://synthetic, relight://tum/<folder>); "
                   "default: the first device");
  live->add_option("--frames", live_options->frames, "Stop after N frames (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  live->add_option("--reconnect-timeout", live_options->reconnect_timeout_s,
                   "Seconds to wait for an unplugged device to come back (the same URI reopened every 0.1 s; "
                   "the run goes on and says so); 0: an unplug ends the run with an error")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  live->add_option("--out", live_options->replay.out, "Output folder")->required();
  live->add_flag("--quiet", live_options->replay.quiet, "No progress or summary on stderr");
  add_frame_options(*live, live_options->replay);
  live->add_option("--markers", live_options->replay.markers,
                   "AprilTag layout for the camera pose: auto (the layout the device's scene describes, relight's "
                   "virtual devices), none, or a layout JSON file")
      ->capture_default_str();
  add_pose_option(*live, live_options->replay);
  add_live_compute_options(*live, live_options->replay);
  add_render_options(*live, live_options->replay);
  add_view_options(*live, live_options->replay);
  runners[live] = [live_options] { return run_live(*live_options); };

  auto record_options = std::make_shared<RecordOptions>();
  CLI::App* record = app.add_subcommand("record", "Record an OpenNI2 device to a .oni file or a TUM RGB-D folder");
  record->add_option("--device", record_options->device, "OpenNI2 device URI or .oni file (default: the first device)");
  record->add_option("--frames", record_options->frames, "Stop after N frames (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  record->add_option("--out", record_options->out, "FILE.oni (openni::Recorder, lossless) or a folder (TUM RGB-D)")
      ->required();
  record->add_flag("--quiet", record_options->quiet, "No progress or summary on stderr");
  runners[record] = [record_options] { return run_record(*record_options); };
}

}  // namespace relight::app
