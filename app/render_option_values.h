#pragma once
// The fixed-value options of the rendering part of replay and live (commands.cpp checks them,
// replay.cpp parses them): each list of names exists here only.
#include "option_values.h"
#include "relight/colormap/colormap_stages.h"
#include "relight/colormap/sample_mapping.h"
#include "relight/render/vpl/vpl.h"

namespace relight::app {

inline constexpr std::array<OptionValue<render::VplBudget>, 4> kVplBudgets{{{"equal", render::VplBudget::Equal},
                                                                            {"power", render::VplBudget::ByPower},
                                                                            {"weights", render::VplBudget::ByWeight},
                                                                            {"flux", render::VplBudget::ByPreviousFlux}}};
inline constexpr std::array<OptionValue<render::BounceMethod>, 2> kBounceMethods{
    {{"rays", render::BounceMethod::RayTraced}, {"cone", render::BounceMethod::PointCone}}};
inline constexpr std::array<OptionValue<render::VplSource>, 2> kVplSources{
    {{"rays", render::VplSource::RayTraced}, {"rsm", render::VplSource::ReflectiveShadowMaps}}};
inline constexpr std::array<OptionValue<colormap::ColorMapMethod>, 3> kColorMapMethods{
    {{"none", colormap::ColorMapMethod::None},
     {"sample", colormap::ColorMapMethod::Sample},
     {"stats", colormap::ColorMapMethod::Statistics}}};
inline constexpr std::array<OptionValue<colormap::PolynomialModel>, 3> kColorMapModels{
    {{"per_channel_affine", colormap::PolynomialModel::PerChannelAffine},
     {"linear_3x3", colormap::PolynomialModel::Linear3x3},
     {"affine_3x4", colormap::PolynomialModel::Affine3x4}}};

}  // namespace relight::app
