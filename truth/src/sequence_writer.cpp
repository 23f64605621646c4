// Writes a synthetic sequence as a TUM RGB-D folder with ground truth (sequence_writer.h).
#include "relight/truth/sequence_writer.h"

#include <algorithm>

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

void write_ground_truth(const fs::path& out, Timestamp timestamp, const synth::RenderedFrame& frame) {
  const std::string stem = fs::path(capture::TumWriter::file_name(timestamp)).stem().string();
  write_depth_exr(out / "gt" / "depth" / (stem + ".exr"), frame.depth);
  write_radiance(out / "gt" / "normals" / (stem + ".exr"), as_radiance_image(frame.normals));
  write_color(out / "gt" / "albedo" / (stem + ".png"), synth::encode_albedo(frame.albedo));
  write_label_png(out / "gt" / "material" / (stem + ".png"), frame.material);
}

void create_folders(const fs::path& out, bool ground_truth) {
  std::error_code ec;
  fs::create_directories(out, ec);
  for (const char* sub : {"depth", "normals", "albedo", "material"}) {
    if (ground_truth && !ec) fs::create_directories(out / "gt" / sub, ec);
  }
  if (ec) throw Error("cannot create " + out.string() + ": " + ec.message());
}

}  // namespace

void write_sequence(const synth::SynthOptions& options, const fs::path& out, const synth::SynthProgress& progress) {
  write_sequence(synth::default_indoor_scene(), options, out, progress);
}

void write_sequence(const synth::Scene& scene, const synth::SynthOptions& options, const fs::path& out,
                    const synth::SynthProgress& progress) {
  synth::validate_synth_options(options);
  create_folders(out, options.ground_truth);
  const PinholeIntrinsics intrinsics = synth::synth_intrinsics(options);
  const std::vector<Pose> poses = synth::make_trajectory(options.trajectory, options.frames, options.seed, scene);
  capture::TumWriter writer(out, synth::kSynthDepthScale);
  for (int i = 0; i < options.frames; ++i) {
    const synth::RenderedFrame frame = synth::render_frame(scene, intrinsics, poses[static_cast<std::size_t>(i)], options.threads);
    const DepthMap depth = options.noise == synth::NoiseModel::None
                               ? frame.depth
                               : synth::apply_kinect_noise(frame.depth, frame.normals, intrinsics, options.kinect,
                                                    options.seed, static_cast<std::uint64_t>(i), options.threads);
    const Timestamp timestamp = synth::frame_timestamp(i);
    writer.add(timestamp, synth::encode_color(frame.radiance, options.color), depth, poses[static_cast<std::size_t>(i)]);
    if (options.ground_truth) write_ground_truth(out, timestamp, frame);
    if (progress) progress(i + 1, options.frames);
  }
  writer.finish();
  if (options.probe) write_radiance(out / "probe.hdr", synth::render_probe(scene, synth::default_probe(scene), options.threads));
  write_file_atomically(out / "scene.json", synth::scene_json(scene, options));
}

}  // namespace relight::truth
