#include "tapping_sweep_parameter.hpp"

#include <algorithm>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "afmkit/core/error.hpp"
#include "tapping_params.hpp"

namespace afmkit::cli {

namespace {

/// The numeric keys of the tapping model (cantilever, drive, law) other than the separation.
std::vector<std::string> sweepable_model_keys() {
  io::ParamSet scratch;
  add_tapping_model_params(scratch);
  std::vector<std::string> keys;
  for (const auto& d : scratch.describe())
    if (d.kind == "real" && d.key != "separation") keys.push_back(d.key);
  return keys;
}

/// The keys of `keys` this run uses (recorded: its unit system, its law).
std::vector<std::string> sweepable_keys_of_run(const io::ParamSet& p, const std::vector<std::string>& keys) {
  const nlohmann::json recorded = p.to_json();
  std::vector<std::string> out;
  for (const std::string& k : keys)
    if (recorded.contains(k)) out.push_back(k);
  return out;
}

}  // namespace

std::vector<std::string> sweep_parameter_names() {
  std::vector<std::string> names{"separation", "drive_frequency"};
  for (const std::string& k : sweepable_model_keys()) names.push_back(k);
  return names;
}

SweptParameter swept_parameter_from(const io::ParamSet& p, std::shared_ptr<const impact::ForceLawModel> law_object) {
  const std::string name = p.text("parameter");
  std::vector<std::string> allowed{"drive_frequency"};
  for (const std::string& k : sweepable_keys_of_run(p, sweepable_model_keys())) allowed.push_back(k);
  if (std::find(allowed.begin(), allowed.end(), name) == allowed.end())
    throw InvalidParameter("parameter", fmt::format("parameter = {} is not a parameter of this run (units = {}, law = "
                                                    "{}): one of separation, {}",
                                                    name, p.text("units"), p.text("law"), fmt::join(allowed, ", ")));
  for (const char* key : {"parameter_min", "parameter_max"})
    if (!p.was_set(key))
      throw InvalidParameter(key, fmt::format("{} is needed with parameter = {} (the range of the sweep, in the unit "
                                              "of {})",
                                              key, name, name));
  for (const char* key : {"separations", "separations_file"})
    if (p.was_set(key))
      throw InvalidParameter(key, fmt::format("{} applies only with parameter = separation (this run sweeps {} over "
                                              "[parameter_min, parameter_max])",
                                              key, name));
  SweptParameter out{tapping::SweepParameter::separation(), name, "", p.real("parameter_min"), p.real("parameter_max")};
  if (name == "drive_frequency") {
    // ω/ω_n, the drive force Γ of the run held (a resonance curve)
    out.unit = "dimensionless";  // ω/ω_n
    out.parameter = tapping::SweepParameter("drive_frequency", [](const tapping::TappingModel& base, double ratio) {
      if (!(ratio > 0.0 && ratio <= 1e3))
        throw InvalidParameter("drive_frequency", fmt::format("drive_frequency = {} is out of range: ω/ω_n in (0, 1000]",
                                                              ratio));
      return tapping::TappingModel(base.cantilever,
                                   tapping::Drive(base.drive.amplitude, ratio * base.cantilever.natural_frequency),
                                   base.law, base.separation);
    });
  } else {
    // the run with the key set to the value (its range checked by the parameter set, its unit converted by the
    // model builder as for any run)
    out.unit = p.unit_of(name);
    const auto run = std::make_shared<const io::ParamSet>(p);
    out.parameter = tapping::SweepParameter(name, [run, name, law_object](const tapping::TappingModel&, double value) {
      io::ParamSet at = *run;
      at.set_value(name, value);
      return tapping_model_from(at, law_object);
    });
  }
  const tapping::TappingModel base = tapping_model_from(p, law_object);
  for (const char* key : {"parameter_min", "parameter_max"}) {
    const double v = p.real(key);
    try {
      (void)out.parameter.at(base, v);
    } catch (const InvalidParameter& e) {
      throw InvalidParameter(key, fmt::format("{} = {} is outside the allowed range of {}: {}", key, v, name, e.what()));
    }
  }
  if (!(out.min < out.max))
    throw InvalidParameter("parameter_min", fmt::format("parameter_min = {} is out of range: must be < parameter_max "
                                                        "= {}",
                                                        out.min, out.max));
  return out;
}

}  // namespace afmkit::cli
