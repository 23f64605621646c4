#pragma once
// Real light that changes during a synthetic sequence: the ground truth for relight's dynamic
// light (probe stream, per-frame extraction, smoothing). One of the scene's point lights (the
// animated light, the key light by default) changes with the frame index i of n:
//   switch-on    off (intensity 0) before frame k, as in the scene from frame k on
//   switch-off   as in the scene before frame k, off from frame k on
//   dim          intensity scaled linearly from 1 at frame 0 to `dim_to` at the last frame
//   orbit        position turned about the vertical axis through Scene::look_at by
//                orbit_degrees * i / (n - 1) (horizontal distance kept; the height too unless
//                orbit_height says otherwise: a low light casts long shadows, whose
//                direction a test can read)
// k = `event_frame`, by default n / 2. A light that is off is left out of the frame's lights
// (the probe shows no emitter there; the rest of the scene is unchanged).
//   pocket-lamp  a real spot light added to the scene's lights: a hand-held lamp (dissertation
//                §5.2.12, Knecht 2010 §6) above the far side of the table, tracked through a
//                tag36h11 tag of its own (id 1) on a card the lamp is fixed to. Lamp and card
//                turn together about the vertical through the card by orbit_degrees over the
//                sequence (from -orbit/2 at frame 0 to +orbit/2 at the last), so the lamp's
//                light sweeps across the table; the card faces the default camera path.
#include <array>

#include "relight/core/named_values.h"
#include "relight/synth/scene.h"

namespace relight::synth {

enum class LightAnimation { None, SwitchOn, SwitchOff, Dim, Orbit, PocketLamp };
inline constexpr std::array<NamedValue<LightAnimation>, 6> kLightAnimationNames{
    {{"none", LightAnimation::None},
     {"switch-on", LightAnimation::SwitchOn},
     {"switch-off", LightAnimation::SwitchOff},
     {"dim", LightAnimation::Dim},
     {"orbit", LightAnimation::Orbit},
     {"pocket-lamp", LightAnimation::PocketLamp}}};

struct LightAnimationOptions {
  LightAnimation kind = LightAnimation::None;
  int light = 0;              ///< index into Scene::lights
  int event_frame = -1;       ///< switch-on/off frame k; < 0: frames / 2
  double dim_to = 0.25;       ///< dim: the last frame's intensity factor
  double orbit_degrees = 90;  ///< orbit, pocket-lamp: the turn over the whole sequence
  double orbit_height = 0;    ///< orbit: the light's height above the floor in metres; 0 keeps the scene's
};

/// The hand-held lamp of the pocket-lamp animation: its light is rigidly fixed to the tag, so
/// the light's position and axis in the tag's frame (x right, y down in the tag image, z into
/// the tag) are the lamp's calibration - what `relight replay --real-spot-tag` is given.
struct PocketLamp {
  TagDecal tag;      ///< id 1; `object` is the card's index once added to a scene
  Rect card;         ///< the card the tag is printed on (its white margin and a border)
  PointLight light;  ///< the spot light
  Eigen::Vector3d position_in_tag;
  Eigen::Vector3d axis_in_tag;
};

/// The pocket lamp of `scene` turned by `degrees` about the vertical through its card (0: aimed
/// at the scene's table tag). The calibration (position_in_tag, axis_in_tag) is the same at
/// every angle.
[[nodiscard]] PocketLamp pocket_lamp(const Scene& scene, double degrees);

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
