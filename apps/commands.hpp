#pragma once
// Registration of the subcommands of the `afmkit` program. Each domain owns its own file in apps/.
namespace CLI {
class App;
}

namespace afmkit::cli {

void register_impact(CLI::App& app);            // impact_cmd.cpp:        afmkit impact
void register_tapping(CLI::App& app);           // tapping_cmd.cpp:       afmkit tapping …
void register_tapping_orbit(CLI::App& tapping); // tapping_orbit_cmd.cpp: afmkit tapping orbit
void register_tapping_hb(CLI::App& tapping);    // tapping_hb_cmd.cpp:    afmkit tapping hb
void register_tapping_sweep(CLI::App& tapping); // tapping_sweep_cmd.cpp: afmkit tapping sweep
void register_tapping_grid(CLI::App& tapping);  // tapping_grid_cmd.cpp:  afmkit tapping grid (OpenMP, Zarr)
void register_tapping_fm(CLI::App& tapping);    // tapping_fm_cmd.cpp:    afmkit tapping fm (FM-AFM)
void register_tapping_image(CLI::App& tapping); // tapping_image_cmd.cpp: afmkit tapping image (AM imaging)
void register_tapping_modes(CLI::App& tapping); // tapping_modes_cmd.cpp: afmkit tapping modes (2-3 eigenmodes)
void register_control(CLI::App& app);           // control_cmd.cpp:       afmkit control …
void register_control_tf(CLI::App& control);        // control_tf_cmd.cpp:       control tf
void register_control_analysis(CLI::App& control);  // control_analysis_cmd.cpp: control roots|margin|chart|tune
void register_control_simulate(CLI::App& control);  // control_simulate_cmd.cpp: control simulate
void register_control_export(CLI::App& control);    // control_export_cmd.cpp:   control export (C header)
void register_demo(CLI::App& app);              // demo_cmd.cpp:          afmkit demo (the Quick-start main job)
void register_scan(CLI::App& app);              // scan_cmd.cpp:          afmkit scan
void register_report(CLI::App& app);            // report_cmd.cpp:        afmkit report (the Python report)
void register_study(CLI::App& app);             // study_cmd.cpp:         afmkit study run (Python + Dask)
void register_spectroscopy(CLI::App& app);      // spectroscopy_cmd.cpp:  afmkit spectroscopy …
void register_spectroscopy_prepare(CLI::App& spectroscopy);  // spectroscopy_prepare_cmd.cpp: spectroscopy prepare
void register_spectroscopy_fit(CLI::App& spectroscopy);  // spectroscopy_fit_cmd.cpp: spectroscopy fit
void register_spectroscopy_reconstruct(CLI::App& spectroscopy);  // spectroscopy_reconstruct_cmd.cpp

}  // namespace afmkit::cli
