// afmkit control export: the real-time first-harmonic-rejection filter (RealtimeFilter, zero-order-hold form) as a C
// header for the freestanding embedded core (include/afmkit/embed/afmkit_embed.h; docs/embedding.md):
//   afmkit control export --format c-header --output filter.h --sample-rate 20000 --rotation-frequency 314.159 …
// Controller and plant options (and TOML keys) are those of `afmkit control simulate` / `tune` (control_params.hpp:
// rates in units of Ω, delays in units of T); the bank controller only. The design is refused (exit 2, message naming
// the parameter and its allowed range) when the closed loop with the declared plant and delay (plus one sample) is
// not stable, when it does not fit --target-memory, below the Nyquist rate of the highest harmonic, or (float) when a
// damped mode's decay per sample is not resolved by float. The header is verified on the host (the core run on its
// test vectors) before it is written, atomically (temporary file + rename).
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/control/settings.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/embed/c_header.hpp"
#include "afmkit/embed/design.hpp"
#include "afmkit/io/output.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "control_params.hpp"
#include "control_units.hpp"
#include "unit_tagged.hpp"

namespace afmkit::cli {

namespace {

embed::ExportSpec export_spec_from(const io::ParamSet& p, const control::ControlSettings& c) {
  if (c.controller != control::ControllerKind::Bank)
    throw InvalidParameter("controller", fmt::format("controller = {} cannot be exported: must be bank (the "
                                                     "RealtimeFilter's bank of N oscillators, couplings eq. 20)",
                                                     control::to_string(c.controller)));
  const control::ControlSettingsSi si = control::to_si(c);
  embed::ExportSpec s;
  s.sample_rate = p.real("sample_rate");
  if (!(s.sample_rate > 0.0))
    throw InvalidParameter("sample_rate", fmt::format("sample_rate is required: must be > N*Omega/pi = {} samples/s "
                                                      "(Nyquist for harmonic N = {}) and finite",
                                                      c.harmonics * si.rotation_frequency / std::numbers::pi, c.harmonics));
  s.rotation_frequency = si.rotation_frequency;
  s.harmonics = c.harmonics;
  s.alpha = si.alpha;
  s.beta = si.beta;
  s.gain = si.gain;
  s.rejected = c.rejected;
  s.plant = c.plant;
  s.plant_rate = si.plant_rate;
  s.delay = si.delay;
  s.precision = embed::precision_from(p.text("precision"));
  s.input_limit = p.real("input_limit");
  s.target_memory = static_cast<std::size_t>(p.integer("target_memory"));
  return s;
}

void run_export(const io::ParamSet& p, Captured* capture) {
  const control::ControlSettings c = control_settings_from(p);
  const std::string path = p.text("output");
  if (path.empty()) throw InvalidParameter("output", "output is required: the path of the C header to write (FILE.h)");
  const embed::ExportSpec spec = export_spec_from(p, c);
  const auto samples = static_cast<std::size_t>(p.integer("test_vectors"));
  // test vectors: 8 bytes (expected) + one number (input) each, held in memory twice (vectors and text, ~40 B each)
  require_memory("test_vectors", static_cast<double>(samples), 80.0);
  const std::string header = embed::export_c_header(spec, samples);
  const embed::ExportedDesign design(spec);  // the same design again, for the summary (deterministic)
  io::write_file_atomic(path, header);
  const embed::CoreFootprint fp = design.footprint();
  const ControlUnits cu(control::RotationUnits(spec.rotation_frequency));
  UnitTagged tagged;
  tagged.add("output", path)
      .add("format", p.text("format"))
      .add("precision", embed::to_string(spec.precision))
      .add("state_size", design.state_size(), "count")
      .add("damped_pairs", design.pairs(), "count")
      .add("undamped_pairs", design.circles(), "count")
      .add("real_modes", design.reals(), "count")
      .add("memory_bytes",
           {{"total", fp.total()}, {"coefficient_struct", fp.coefficient_struct},
            {"coefficient_arrays", fp.coefficient_arrays}, {"state", fp.state}, {"filter_struct", fp.filter_struct}},
           "bytes")
      .add("spectral_abscissa", design.spectral_abscissa(), cu.omega)
      .add("smallest_decay_per_sample", design.smallest_decay(), "dimensionless")
      .add("test_vectors", samples, "count");
  const nlohmann::json j = tagged.with_units();
  if (capture != nullptr) {
    capture->results = j;
    // the parameters as run: gain / model_rate / model_delay as used, the precision's input limit when 0 was given
    io::ParamSet as_run = params_as_run(p, c);
    if (p.real("input_limit") == 0.0) as_run.record_used("input_limit", spec.resolved_input_limit());
    capture->parameters = as_run.to_json();
    return;
  }
  if (p.flag("json")) {
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("wrote {}: {} core, N = {}, {} state numbers, {} bytes (coefficients {} + state {} + handle {}), "
             "spectral abscissa {}{}\n",
             path, embed::to_string(spec.precision), spec.harmonics, design.state_size(), fp.total(),
             fp.coefficient_struct + fp.coefficient_arrays, fp.state, fp.filter_struct,
             rate_summary(design.spectral_abscissa(), control::RotationUnits(spec.rotation_frequency)),
             samples ? fmt::format(", {} test vectors", samples) : std::string());
}

}  // namespace

void register_control_export(CLI::App& control) {
  add_command(
      control, "export",
      "export the real-time filter (zero-order-hold, modal form) as a C header for the freestanding embedded core "
      "(afmkit/embed/afmkit_embed.h, docs/embedding.md); refuses unstable, oversized or float-unresolvable designs",
      [](io::ParamSet& p) {
        add_control_params(p, kMaxHarmonicsSpectra);
        p.group("Sampling")
            .real("sample_rate", 0.0, "sample rate f_s of the filter on the target; must exceed N*Omega/pi",
                  io::Range::non_negative())
            .unit("samples/s")
            .default_text("required")
            .real("input_limit", 0.0, "largest accepted |measured sample|; larger ones (and NaN, inf) are skipped, "
                                      "output held", io::Range::non_negative())
            .unit("signal")
            .default_text("1e15 (float), 1e150 (double)");
        p.group("Export")
            .text("format", "c-header", "output format", {"c-header"})
            .file("output", "", "path of the C header to write (written atomically)")
            .writes()
            .default_text("required")
            .text("precision", "float", "precision of the embedded core: float (32-bit) or double (64-bit)",
                  {"float", "double"})
            .integer("test_vectors", 0, "number M of test samples (input and expected closed-loop signal) to embed; "
                                        "0: none (a target holds 12 bytes per sample in float, 16 in double)", 0, 1000000)
            .integer("target_memory", 0, "bytes available for one filter (coefficients + state + handle); 0: no "
                                         "limit", 0, 1099511627776L)
            .unit("bytes");
        add_json_flag(p, "print the summary as JSON");
      },
      with_si_inputs(run_export));
}

}  // namespace afmkit::cli
