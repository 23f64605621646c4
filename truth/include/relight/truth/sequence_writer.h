#pragma once
// Renders a synthetic sequence (synth/sequence.h: the options, the files, scene.json) and writes
// it as a TUM RGB-D folder with ground truth, through capture's TumWriter. Everything is a pure
// function of the options: the same options give byte-identical files.
#include <filesystem>

#include "relight/synth/scene.h"
#include "relight/synth/sequence.h"

namespace relight::truth {

/// Renders and writes the sequence of synth::default_indoor_scene() into `out` (created if
/// needed). Throws relight::Error on bad options or when a file cannot be written.
void write_sequence(const synth::SynthOptions& options, const std::filesystem::path& out,
                    const synth::SynthProgress& progress = {});
void write_sequence(const synth::Scene& scene, const synth::SynthOptions& options, const std::filesystem::path& out,
                    const synth::SynthProgress& progress = {});

}  // namespace relight::truth
