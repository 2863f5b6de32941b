// afmkit report: every figure of both papers and the figures beyond them, computed with afmkit, in one HTML page
// (out/report/index.html). The report is the Python package afmkit.report (python/afmkit/report/, Matplotlib): this
// command validates its parameters and hands over to the Python interpreter afmkit was built with.
#include <string>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "python_launch.hpp"

namespace afmkit::cli {

namespace {

void run_report(const io::ParamSet& p, Captured*) {
  io::require_writable_folder("output_dir", p.text("output_dir"), p.text("output_dir"));  // Python creates it
  exec_python_module("report", {"--output-dir", p.text("output_dir"), "--jobs", std::to_string(p.integer("jobs")),
                                "--figures", p.text("figures")});
}

}  // namespace

void register_report(CLI::App& app) {
  add_command(
      app, "report",
      "every figure of both papers and beyond, computed with afmkit, in one HTML page (out/report/index.html) "
      "with captions and a table of key numbers; Python + Matplotlib, a few seconds on 2 cores",
      [](io::ParamSet& p) {
        p.group("Report")
            .file("output_dir", "out/report", "folder the report is written to (index.html and the figures' PNG "
                                              "files); index.html is replaced only when the report is complete")
            .writes([](const std::string& dir) {
              return std::vector<io::WrittenPath>{{dir + "/index.html"}, {dir + "/figures", true}};
            })
            .integer("jobs", 2, "figures computed at the same time (processes)", 1, 64)
            .text("figures", "all",
                  "'all', or a comma-separated list of figure ids (seed000-fig3, seed003-fig2, beyond-tuning, …: "
                  "docs/report.md lists them); an unknown id is refused before anything is computed");
      },
      run_report);
}

}  // namespace afmkit::cli
