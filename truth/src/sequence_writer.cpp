// Writes a synthetic sequence as a TUM RGB-D folder with ground truth (sequence_writer.h).
#include "relight/truth/sequence_writer.h"

#include <algorithm>
#include <optional>

#include "relight/capture/tum_writer.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"

namespace relight::truth {

namespace {

namespace fs = std::filesystem;

RadianceImage as_radiance_image(const NormalMap& normals) {
  RadianceImage image(normals.width(), normals.height());
  std::copy(normals.pixels().begin(), normals.pixels().end(), image.pixels().begin());
  return image;
}

std::string stem_of(Timestamp timestamp) { return fs::path(capture::TumWriter::file_name(timestamp)).stem().string(); }

void write_ground_truth(const fs::path& out, Timestamp timestamp, const synth::RenderedFrame& frame) {
  const std::string stem = stem_of(timestamp);
  write_depth_exr(out / "gt" / "depth" / (stem + ".exr"), frame.depth);
  write_radiance(out / "gt" / "normals" / (stem + ".exr"), as_radiance_image(frame.normals));
  write_color(out / "gt" / "albedo" / (stem + ".png"), synth::encode_albedo(frame.albedo));
  write_label_png(out / "gt" / "material" / (stem + ".png"), frame.material);
}

void create_folders(const fs::path& out, const synth::SynthOptions& options, bool animated, bool per_frame_probes) {
  std::error_code ec;
  fs::create_directories(out, ec);
  for (const char* sub : {"depth", "normals", "albedo", "material", "lights"}) {
    const bool wanted = options.ground_truth && (animated || std::string_view(sub) != "lights");
    if (wanted && !ec) fs::create_directories(out / "gt" / sub, ec);
  }
  if (per_frame_probes && !ec) fs::create_directories(out / "probe", ec);
  if (ec) throw Error("cannot create " + out.string() + ": " + ec.message());
}

}  // namespace

void write_sequence(const synth::SynthOptions& options, const fs::path& out, const synth::SynthProgress& progress) {
  write_sequence(synth::default_indoor_scene(), options, out, progress);
}

void write_sequence(const synth::Scene& scene, const synth::SynthOptions& options, const fs::path& out,
                    const synth::SynthProgress& progress) {
  synth::validate_synth_options(options);
  const bool animated = options.light_animation.kind != synth::LightAnimation::None;
  if (animated && options.frames > 0) (void)synth::scene_at_frame(scene, options.light_animation, 0, options.frames);
  // Every frame has its own probe when the light changes or the probe camera is noisy.
  const bool per_frame_probes = options.probe && (animated || options.probe_noise > 0.0);
  create_folders(out, options, animated, per_frame_probes);
  std::optional<RadianceImage> still_probe;  // not animated: rendered once, noisy per frame
  std::optional<RadianceImage> first_probe;  // frame 0's clean probe: probe.hdr
  const PinholeIntrinsics intrinsics = synth::synth_intrinsics(options);
  const std::vector<Pose> poses = synth::make_trajectory(options.trajectory, options.frames, options.seed, scene);
  capture::TumWriter writer(out, synth::kSynthDepthScale);
  std::string probe_list = "# relight synth: the light probe of every frame (timestamp filename)\n";
  for (int i = 0; i < options.frames; ++i) {
    const synth::Scene frame_scene = synth::scene_at_frame(scene, options.light_animation, i, options.frames);
    const synth::RenderedFrame frame =
        synth::render_frame(frame_scene, intrinsics, poses[static_cast<std::size_t>(i)], options.threads);
    const DepthMap depth = options.noise == synth::NoiseModel::None
                               ? frame.depth
                               : synth::apply_kinect_noise(frame.depth, frame.normals, intrinsics, options.kinect,
                                                    options.seed, static_cast<std::uint64_t>(i), options.threads);
    const Timestamp timestamp = synth::frame_timestamp(i);
    const ColorImage color = synth::add_color_noise(
        synth::encode_color(synth::blur_radiance(frame.radiance, options.camera.blur_sigma_px), options.color),
        options.camera, options.seed, static_cast<std::uint64_t>(i), options.threads);
    writer.add(timestamp, color, depth, poses[static_cast<std::size_t>(i)]);
    if (options.ground_truth) write_ground_truth(out, timestamp, frame);
    const std::string stem = stem_of(timestamp);
    if (animated && options.ground_truth) {
      write_file_atomically(out / "gt" / "lights" / (stem + ".json"), synth::frame_lights_json(frame_scene));
    }
    if (per_frame_probes) {
      const std::string name = "probe/" + stem + ".hdr";
      if (animated || !still_probe) {
        still_probe = synth::render_probe(frame_scene, synth::default_probe(frame_scene), options.threads);
      }
      if (i == 0) first_probe = still_probe;
      write_radiance(out / name, synth::add_probe_noise(*still_probe, options.probe_noise, options.seed,
                                                        static_cast<std::uint64_t>(i)));
      probe_list.append(stem).append(" ").append(name).append("\n");
    }
    if (progress) progress(i + 1, options.frames);
  }
  writer.finish();
  if (options.probe) {
    // Per-frame probes already rendered frame 0's; otherwise the scene's (frame 0's) is rendered now.
    if (!first_probe) first_probe = synth::render_probe(scene, synth::default_probe(scene), options.threads);
    write_radiance(out / "probe.hdr", *first_probe);
    if (per_frame_probes) write_file_atomically(out / "probe.txt", probe_list);
  }
  write_file_atomically(out / "scene.json", synth::scene_json(scene, options));
}

}  // namespace relight::truth
