#pragma once
// Real light that changes during a synthetic sequence: the ground truth for relight's dynamic
// light (probe stream, per-frame extraction, smoothing). One of the scene's point lights (the
// animated light, the key light by default) changes with the frame index i of n:
//   switch-on    off (intensity 0) before frame k, as in the scene from frame k on
//   switch-off   as in the scene before frame k, off from frame k on
//   dim          intensity scaled linearly from 1 at frame 0 to `dim_to` at the last frame
//   orbit        position turned about the vertical axis through Scene::look_at by
//                orbit_degrees * i / (n - 1) (height and distance kept)
// k = `event_frame`, by default n / 2. A light that is off is left out of the frame's lights
// (the probe shows no emitter there; the rest of the scene is unchanged).
#include <array>

#include "relight/core/named_values.h"
#include "relight/synth/scene.h"

namespace relight::synth {

enum class LightAnimation { None, SwitchOn, SwitchOff, Dim, Orbit };
inline constexpr std::array<NamedValue<LightAnimation>, 5> kLightAnimationNames{
    {{"none", LightAnimation::None},
     {"switch-on", LightAnimation::SwitchOn},
     {"switch-off", LightAnimation::SwitchOff},
     {"dim", LightAnimation::Dim},
     {"orbit", LightAnimation::Orbit}}};

struct LightAnimationOptions {
  LightAnimation kind = LightAnimation::None;
  int light = 0;              ///< index into Scene::lights
  int event_frame = -1;       ///< switch-on/off frame k; < 0: frames / 2
  double dim_to = 0.25;       ///< dim: the last frame's intensity factor
  double orbit_degrees = 90;  ///< orbit: the turn over the whole sequence
};

/// The scene as frame `frame` of `frames` sees it. Throws relight::Error on options that name
/// no light of the scene or make no sense (dim_to outside [0, 1], a switch frame past the end).
[[nodiscard]] Scene scene_at_frame(const Scene& scene, const LightAnimationOptions& animation, int frame, int frames);

/// The light animation scene.json describes (its "light_animation" section, none when absent) and
/// the sequence's frame count: what a reader needs for scene_at_frame. Throws relight::Error
/// naming `source` on malformed JSON or an unknown animation.
struct SequenceLightAnimation {
  LightAnimationOptions animation;
  int frames = 0;
};
[[nodiscard]] SequenceLightAnimation light_animation_of_scene_json(const std::string& text, const std::string& source);

/// The switch frame k the options mean for `frames` frames.
[[nodiscard]] int light_event_frame(const LightAnimationOptions& animation, int frames);

}  // namespace relight::synth
