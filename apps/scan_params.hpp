#pragma once
// Parameters of `afmkit scan` (docs/commands.md#scan, docs/scan.md): the sample, the spiral, the plant and actuator,
// the detector, the controller and the images, all in SI units (m, s, Hz, rad/s) except the couplings α, β (units of
// Ω, as in `afmkit control`) and the tilt (degrees).
#include <string>
#include <vector>

#include "afmkit/io/params.hpp"
#include "afmkit/scan/instrument.hpp"
#include "afmkit/scan/surface.hpp"

namespace afmkit::cli {

void add_scan_params(io::ParamSet& p);
/// The "Sample" group alone (the generators, the file, the tilt): the one declaration of the samples every scanning
/// command shares (`scan`, `tapping image`); a command sets its own defaults with ParamSet::set_default.
void add_sample_params(io::ParamSet& p);
/// The sample's topography without tilt, centred on (0, 0): a file (GSF, ASCII matrix, 16-bit PNG) or a generator
/// on a square of side `generated_size` [m] (InvalidParameter naming the parameter).
scan::HeightMap sample_map_from(const io::ParamSet& p, double generated_size);
/// The bytes the sample map needs; InvalidParameter (sample_resolution or sample_file) when it alone does not fit.
double require_sample_memory(const io::ParamSet& p);
/// The applies_when declarations of the sample's keys (each generator's keys for that generator, the file's for
/// sample = file).
void record_only_sample_keys_that_apply(io::ParamSet& p);
/// The instrument given (validated: InvalidParameter naming the parameter).
scan::InstrumentSpec instrument_from(const io::ParamSet& p);
/// The side [m] of a generated sample: sample_size when given, else 2.04 x end_radius.
double generated_sample_size(const io::ParamSet& p);
/// The sample: a built-in generator or a file (GSF, ASCII matrix, 16-bit PNG) centred on the spindle axis, tilted.
scan::Surface surface_from(const io::ParamSet& p);
/// Refuses (InvalidParameter, before anything is read or allocated) a scan whose sample map and images need more
/// memory than the machine can give (docs/development.md#memory-and-sizes): names image_resolution,
/// sample_resolution or sample_file and the largest value that fits. `recorded`: only the images (no sample map).
void require_scan_memory(const io::ParamSet& p, bool recorded);
/// Keys that describe the simulated instrument or sample (refused together with `recorded`).
const std::vector<std::string>& simulation_only_keys();
/// Declares which keys apply when (ParamSet::applies_when), so that a run's record lists only those: the
/// simulation's keys without `recorded`, sample_file and sample_z_scale for sample = file, each generator's own
/// keys for that generator. Call after `recorded` is declared.
void record_only_what_applies(io::ParamSet& p);

}  // namespace afmkit::cli
