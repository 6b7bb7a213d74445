#include "app/synth/cli.h"

#include <unistd.h>

#include <cstdio>

namespace pneufem {

std::unique_ptr<SynthCommand> add_synth_command(CLI::App& app) {
  auto c = std::make_unique<SynthCommand>();
  SynthOptions& synth = c->options;
  CLI::App* sy = c->cmd = app.add_subcommand(
      "synth", "Synthetic measurements from a scene with hidden effects, sampled like the rig (pressure 400 Hz, "
               "angle 30 fps, controller overshoot, noise, outlier frames): OUT.csv, OUT.truth.csv, OUT.truth.json");
  sy->add_option("scene", synth.scene_path, "Scene file (TOML); omit for the built-in default pneu-net")
      ->check(CLI::ExistingFile);
  sy->add_option("--hidden", c->hidden,
                 "EFFECT[,EFFECT...] hidden at their truth values (candidates: stiffness, viscoelastic, viscoelastic_instantaneous, viscoelastic_broad, mullins, "
                 "fatigue, fatigue_saturating, pressure_lag, gravity and registered material effects), or none (the control dataset)")
      ->required();
  sy->add_option("--out", synth.out_csv, "Measurement CSV to write (canonical format); truth files go beside it")
      ->required();
  sy->add_option("--set", synth.sets, "Override a scene key, also a hidden effect's value (repeatable)");
  sy->add_option("--seed", synth.seed, "Random seed of the noise (same seed, same file)")->capture_default_str();
  sy->add_option("--threads", synth.threads, "Worker threads (default: all cores); results do not depend on it")
      ->check(CLI::Range(1, 1024));
  sy->add_option("--pressure-rate", synth.pressure_rate_Hz, "Pressure sampling rate (Hz)")->capture_default_str();
  sy->add_option("--angle-rate", synth.angle_rate_Hz, "Angle (video) frame rate (Hz)")->capture_default_str();
  sy->add_option("--controller-hz", synth.controller_hz, "Natural frequency of the inlet controller (Hz)")
      ->capture_default_str();
  sy->add_option("--controller-damping", synth.controller_damping,
                 "Damping ratio of the inlet controller, in (0, 1) (0.65: ~7 % overshoot, 0.3 s rise at 1 Hz)")
      ->capture_default_str();
  sy->add_option("--pressure-noise", synth.pressure_noise_kPa, "Pressure sensor white noise, 1 sigma (kPa)")
      ->capture_default_str();
  sy->add_option("--angle-noise", synth.angle_noise_deg, "Angle tracking white noise, 1 sigma (deg)")
      ->capture_default_str();
  sy->add_option("--outliers", synth.outlier_fraction, "Fraction of frames with a tracking failure (0 = none)")
      ->capture_default_str();
  sy->add_option("--report-every", synth.report_every_s, "Densest spacing of solved model states in holds (s)")
      ->capture_default_str();
  sy->add_option("--inlet-tolerance", synth.inlet_tolerance_kPa,
                 "Piecewise-linear fit of the true inlet pressure that drives the model (kPa)")
      ->capture_default_str();
  return c;
}

int run_synth_command(SynthCommand& c, const std::string& command_line) {
  c.options.hidden = parse_hidden(c.hidden);
  c.options.command_line = command_line;
  c.options.progress = isatty(fileno(stderr));
  c.options.progress_log_every_s = c.options.progress ? 0.0 : 60.0;  // a log gets a line a minute
  const SynthResult r = run_synth(c.options);
  std::printf("synth: %zu trial(s), %ld model states, %d outlier frames, %.1f s; wrote %s (+ .truth.csv, .truth.json)\n",
              r.data.trials.size(), r.states, r.outliers, r.wall_s, c.options.out_csv.c_str());
  return 0;
}

}  // namespace pneufem
