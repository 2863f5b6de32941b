#pragma once
// Pieces shared by `afmkit control roots | margin | chart | tune` (control_analysis_cmd.cpp registers them; chart
// and tune live in control_chart_cmd.cpp and control_tune_cmd.cpp). Units: control_params.hpp (Ω, T).
#include <string>

#include <nlohmann/json.hpp>

#include "afmkit/control/loop_family.hpp"
#include "afmkit/io/params.hpp"

namespace CLI {
class App;
}

namespace afmkit::cli {

/// A window of the coupling plane (x, y) = (a, b) or (alpha, beta), in units of Ω.
struct Window {
  double x_min, x_max, y_min, y_max;
};
/// The window given by x_min … y_max, each defaulting to `single` or `couplings` by the family's kind; InvalidParameter
/// when a maximum is not above its minimum.
Window window_from(const io::ParamSet& params, const control::LoopFamily& family, Window single, Window couplings);
/// Declares x_min, x_max, y_min, y_max (units of Ω) with the defaults window_from() applies: `single` for the
/// single oscillator, `couplings` otherwise (both shown in --help where they differ).
void add_window_params(io::ParamSet& params, const Window& single, const Window& couplings);
nlohmann::json window_json(const Window& window);
/// The window parameters as (key, value) pairs, for params_as_run().
std::vector<std::pair<std::string, double>> window_values(const Window& window);
/// The family in units of Ω and T: "bank N=10 (alpha, beta), K=20 Omega, static plant gamma=20 Omega, tau=0.1 T".
std::string describe_family(const control::LoopFamily& family);

void add_control_chart(CLI::App& control);  // control_chart_cmd.cpp
void add_control_tune(CLI::App& control);   // control_tune_cmd.cpp

}  // namespace afmkit::cli
