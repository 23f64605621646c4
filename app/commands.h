#pragma once
// The subcommands of the relight CLI: each registers its options on a CLI11 subcommand and a
// runner invoked after parsing.
#include <CLI/CLI.hpp>
#include <functional>
#include <map>

namespace relight::app {

struct ReplayOptions;

void register_commands(CLI::App& app);
/// Each subcommand registers its runner in `runners`, keyed by its CLI11 subcommand.
using Runners = std::map<const CLI::App*, std::function<int()>>;
void register_synth(CLI::App& app, Runners& runners);
void register_lights(CLI::App& app, Runners& runners);
/// `relight render-reference` and `relight models` (render_command.cpp).
void register_render(CLI::App& app, Runners& runners);
/// `relight devices`, `relight live` and `relight record` (OpenNI2 devices, live_command.cpp).
void register_live(CLI::App& app, Runners& runners);

/// The options of differential rendering (--object, --place, --lights, ...) shared by replay,
/// live and graph.
void add_render_options(CLI::App& command, ReplayOptions& options);
/// --no-frames and --previews (which per-frame pictures are written), shared by replay and live.
void add_frame_options(CLI::App& command, ReplayOptions& options);
/// --view and --view-side (a window on the final picture), shared by replay and live.
void add_view_options(CLI::App& command, ReplayOptions& options);
/// --pose auto|sequence|marker|odometry|marker+odometry, shared by replay and live.
void add_pose_option(CLI::App& command, ReplayOptions& options);
/// --method2-normals filtered|plain, shared by replay and live.
void add_method2_normals_option(CLI::App& command, ReplayOptions& options);

/// Runs the subcommand that was selected on the command line; returns the exit code.
int run_selected(CLI::App& app);

}  // namespace relight::app
