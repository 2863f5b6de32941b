#pragma once
// Shared controller/plant parameters of the `afmkit control …` commands (seed 2, docs/theory-control.md): the
// command line and TOML form of control::ControlSettings (include/afmkit/control/settings.hpp), whose units are the
// user's: every RATE (alpha, beta, a, b, gain, plant_rate, model_rate) in units of Ω ("Omega"), every DELAY
// (delay, model_delay) in units of the rotation period T = 2π/Ω ("T"), Ω itself (rotation_frequency) in rad/s
// (default 1). Example: alpha = 0.1 means α = 0.1 Ω, delay = 0.1 means τ = 0.1 T. Physical run:
// rotation_frequency = 314.159 (50 Hz), plant_rate = 20 (γ = 20 Ω). Every table and JSON value of these commands
// uses the same units; the sidecars give the resolved settings in both forms ("settings": Ω and T, "settings_si":
// rad/s and s).
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/control/settings.hpp"
#include "afmkit/control/units.hpp"
#include "afmkit/io/params.hpp"
#include "command.hpp"

namespace afmkit::cli {

/// Largest `harmonics` of each command (docs/commands.md states the costs behind them):
///   tf: O(N) per frequency (transfer function as a sum over the oscillators);
///   roots, margin, chart, tune: O(N) per characteristic evaluation, O(N) evaluations per spectrum → O(N²);
///   simulate: O(N²) set-up (controller modes), O(N) per step with more than 2N steps per period.
inline constexpr long kMaxHarmonicsTf = 100000;
inline constexpr long kMaxHarmonicsSpectra = 1000;

/// Adds the shared parameters (with their units) to `params`; `max_harmonics` bounds `harmonics` (and `rejected`).
void add_control_params(io::ParamSet& params, long max_harmonics = kMaxHarmonicsSpectra);
/// The couplings alpha and beta of the bank (eq. 20), in units of Omega: shared by the control commands and scan.
void add_coupling_alpha(io::ParamSet& params);
void add_coupling_beta(io::ParamSet& params);
/// The bank's number N of oscillators (eq. 15), `harmonics`: default 10, in [1, max_harmonics] (each command's
/// bound: its cost in N), `help` saying what N costs there; shared by the control commands and scan.
void add_harmonics_param(io::ParamSet& params, long max_harmonics, const std::string& help);
/// `threads` (OpenMP threads of a grid computation) and the `progress` flag, shared by chart and tune.
void add_threads_param(io::ParamSet& params);
void add_progress_flag(io::ParamSet& params);
/// SI alternatives of the keys in rotation units (docs/commands.md#control-si-keys): for `key` in units of Omega,
/// `key_rad_per_s` [rad/s] (or, with SiUnit::Hz, `key_hz` [Hz]: 2 pi f); in units of T, `key_seconds` [s]; for
/// rotation_frequency [rad/s], `rotation_frequency_hz`. Declared right after `key` (same kind: real or reals), counted
/// only when given (the record then holds it instead of `key`).
enum class SiUnit { Auto, Hz };
void add_si_alternative(io::ParamSet& params, const std::string& key, SiUnit unit = SiUnit::Auto,
                        io::Range range = io::Range::any());
/// `params` with every given SI alternative converted into its key (rotation_frequency first, then the others with
/// that Omega: value / Omega, value / T, 2 pi f / Omega); InvalidParameter naming both when a quantity is given in
/// two forms, naming the SI key when its value converts out of the key's range.
io::ParamSet resolve_si_inputs(const io::ParamSet& params);
/// `run` on resolve_si_inputs(params): what every control command runs.
Run with_si_inputs(Run run);

/// Throws InvalidParameter(parameter, …) when `value` units of `bytes_per_unit` bytes held in memory do not fit in
/// half of the available memory (MemAvailable), before any work.
void require_memory(const std::string& parameter, double value, double bytes_per_unit);
/// Refuses (work_budget.hpp: InvalidParameter naming `parameter`, exit 2) a request of `spectra` closed-loop spectra
/// at a delay of `delay_in_periods` T whose estimate exceeds the work limit: the roots in a search box grow with the
/// delay, so a spectrum costs at least kSpectrumSecondsPerPeriod x (N + 1) x tau/T (docs/commands.md, sizes and costs);
/// checked for delays above one period (below, the other size options' own checks apply).
/// The message names `key`, or its SI form (`key`_seconds, the value in s) when that was given.
void require_delay_work(const io::ParamSet& params, const std::string& key, double delay_in_periods,
                        const control::RotationUnits& units, double spectra, int harmonics, const std::string& what);

/// The settings given (after params.resolve()), validated: InvalidParameter naming the parameter.
control::ControlSettings control_settings_from(const io::ParamSet& params);

/// The resolved settings as given (Ω, T; defaults such as gain = plant_rate filled in), with their "units".
nlohmann::json settings_json(const control::ControlSettings& settings);
/// The same in the library's units (rad/s, s), with their "units".
nlohmann::json settings_si_json(const control::ControlSettings& settings);
/// The parameters as run, for a sidecar: `params` with the defaults that depend on other values resolved (gain,
/// model_rate, model_delay) and `values` (key, value in the parameter's own unit) replacing the given ones.
io::ParamSet params_as_run(const io::ParamSet& params, const control::ControlSettings& settings,
                           const std::vector<std::pair<std::string, double>>& values = {});

/// A rate of a summary line (internally rad/s) said to be normalised, with its physical value: "-0.05 (normalised,
/// units of Omega; -0.157 rad/s)" (docs/units.md#summaries).
std::string rate_summary(double rad_per_s, const control::RotationUnits& units, int digits = 4);
/// A delay or time of a summary line (internally s): "0.31 (normalised, units of T; 6.2 ms)".
std::string delay_summary(double seconds, const control::RotationUnits& units, int digits = 4);

}  // namespace afmkit::cli
