// parallax synth <scene> <out-dir> [--motion M] [--frames N] [--seed S] [--width W --height H]
//                [--exposure] [--noise SIGMA] [--vignette] [--blur] [--texture FILE]...

#include <fmt/format.h>

#include <cstdio>

#include "tools/commands/commands.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax::cli {

void AddSynthCommand(CLI::App& app, int* exit_code) {
  auto options = std::make_shared<synth::SynthOptions>();
  auto out_dir = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("synth", "Render a synthetic sequence in TUM RGB-D layout");
  cmd->add_option("scene", options->scene, "room | desk | corridor | street")
      ->required()
      ->check(CLI::IsMember(synth::SceneNames()));
  cmd->add_option("out-dir", *out_dir, "output folder (created)")->required();
  cmd->add_option("--motion", options->motion, "shake | walk | orbit | rotate | fast | patrol")
      ->check(CLI::IsMember(synth::MotionNames()));
  cmd->add_option("--frames", options->frames, "number of frames")->check(CLI::Range(2, 100000));
  cmd->add_option("--seed", options->seed, "random seed (textures, noise)");
  cmd->add_option("--width", options->width, "image width, pixels")->check(CLI::Range(32, 8192));
  cmd->add_option("--height", options->height, "image height, pixels")->check(CLI::Range(32, 8192));
  cmd->add_option("--fps", options->fps, "frame rate")->check(CLI::PositiveNumber);
  cmd->add_flag("--exposure", options->exposure, "auto-exposure gain changes");
  cmd->add_option("--noise", options->noise_sigma, "Gaussian sensor noise sigma, grey levels")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--vignette", options->vignette, "radial vignetting");
  cmd->add_flag("--blur", options->blur, "motion blur");
  cmd->add_option("--gamma", options->response_gamma,
                  "camera response: grey = 255 (E / 255)^(1 / gamma) (1: linear)")
      ->check(CLI::Range(0.2, 5.0));
  cmd->add_option("--layout", options->layout,
                  "tum_rgbd (default) | tum_mono (images/, times.txt with exposures, camera.txt, "
                  "pcalib.txt, vignette.png)")
      ->check(CLI::IsMember({"tum_rgbd", "tum_mono"}));
  cmd->add_option("--texture", options->textures, "image file(s) replacing procedural textures")
      ->check(CLI::ExistingFile);
  cmd->callback([options, out_dir, exit_code] {
    const synth::SynthSummary summary = synth::WriteSyntheticSequence(*options, *out_dir);
    std::printf(
        "%s", fmt::format("wrote {} frames of '{}' ({} motion, path {:.3f} m) to {} in {:.2f} s\n",
                          summary.frames, options->scene, options->motion, summary.path_length,
                          *out_dir, summary.render_seconds)
                  .c_str());
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
