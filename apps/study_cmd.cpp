// afmkit study run FILE: a parameter study (docs/study.md) described in a TOML file, run serially, on a local Dask
// cluster or on an existing one, results in a Zarr store. The study runner is the Python package afmkit.study
// (python/afmkit/study/, xarray + Zarr + Dask): this command checks what it can here and hands over to the Python
// interpreter afmkit was built with, passing only the options given (the file's [run] table fills the others).
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "python_launch.hpp"

namespace afmkit::cli {

namespace {

namespace fs = std::filesystem;

void check_study_file(const std::string& file) {
  if (file.empty())
    throw InvalidParameter("file", "file: a study TOML file is required (afmkit study run FILE; docs/study.md)");
  std::error_code ec;
  if (!fs::is_regular_file(file, ec) || ::access(file.c_str(), R_OK) != 0)
    throw InvalidParameter("file", fmt::format("file '{}' cannot be read: must be a readable study TOML file", file));
}

/// serial, local, or an address scheme://host[:port] (tcp://, tls://, ucx://, inproc:// as Dask accepts).
void check_scheduler(const std::string& s) {
  const std::size_t sep = s.find("://");
  if (s == "serial" || s == "local" || (sep != std::string::npos && sep > 0 && sep + 3 < s.size())) return;
  throw InvalidParameter("scheduler", fmt::format("scheduler = '{}' is not allowed: must be serial, local, or a Dask "
                                                  "scheduler address such as tcp://host:8786",
                                                  s));
}

/// A file (netcdf) or folder (store) the study will write: its folder must exist or be creatable and writable, and
/// the path itself must not be an existing item of the other kind.
void check_output(const std::string& key, const std::string& path, bool is_folder) {
  std::error_code ec;
  if (fs::exists(path, ec) && fs::is_directory(path, ec) != is_folder)
    throw InvalidParameter(key, fmt::format("{} '{}' cannot be written: it exists and is {}", key, path,
                                            is_folder ? "not a folder" : "a folder"));
  const fs::path parent = fs::path(path).parent_path();
  io::require_writable_folder(key, path, parent.empty() ? "." : parent.string());
}

void run_study(const io::ParamSet& p, Captured*) {
  check_study_file(p.text("file"));
  std::vector<std::string> args = {"run", p.text("file")};
  if (p.was_set("store")) {
    check_output("store", p.text("store"), true);
    args.insert(args.end(), {"--store", p.text("store")});
  }
  if (p.was_set("scheduler")) {
    check_scheduler(p.text("scheduler"));
    args.insert(args.end(), {"--scheduler", p.text("scheduler")});
  }
  if (p.was_set("workers")) args.insert(args.end(), {"--workers", std::to_string(p.integer("workers"))});
  if (p.was_set("chunk_seconds")) args.insert(args.end(), {"--chunk-seconds", fmt::format("{}", p.real("chunk_seconds"))});
  if (p.was_set("chunk_points")) args.insert(args.end(), {"--chunk-points", std::to_string(p.integer("chunk_points"))});
  if (p.was_set("netcdf") && !p.text("netcdf").empty()) {
    check_output("netcdf", p.text("netcdf"), false);
    args.insert(args.end(), {"--netcdf", p.text("netcdf")});
  }
  if (p.flag("quiet")) args.push_back("--quiet");
  exec_python_module("study", args);
}

}  // namespace

void register_study(CLI::App& app) {
  CLI::App& study = add_command_group(
      app, "study", "parameter studies: grids of orbits, sweeps, HB curves and controller analyses, on one core, "
                    "all cores or a Dask cluster, results as labelled arrays in Zarr (docs/study.md)");
  add_command(
      study, "run",
      "run (or resume) the study described in a TOML file: named axes, the computation at each point, the outputs; "
      "results in a Zarr store (xarray), chunks written as they finish; Python (Dask for a cluster)",
      [](io::ParamSet& p) {
        p.group("Study")
            .file("file", "", "the study's TOML file: name, computation, outputs, [parameters], [axes] and an "
                              "optional [run] table with the options below (docs/study.md)")
            .positional()
            .default_text("none: required");
        p.group("Run (each overrides the file's [run] table)")
            .file("store", "", "Zarr store the results go to; an existing store of the same study is resumed "
                               "(only chunks not finished are computed), one of another study is refused")
            .writes([](const std::string& store) { return std::vector<io::WrittenPath>{{store, true}}; })
            .default_text("the file's [run] store, else out/<name>.zarr")
            .text("scheduler", "local",
                  "where the chunks are computed: serial (this process), local (worker processes on this machine, "
                  "one per core, when the study is long enough for them to pay: docs/study.md) or the address of a "
                  "running Dask scheduler, tcp://host:8786")
            .default_text("the file's [run] scheduler, else local")
            .integer("workers", 1, "worker processes of the local pool", 1, 4096)
            .default_text("one per core")
            .real("chunk_seconds", 1.0, "computation per chunk, measured on the first points; each chunk is one call "
                                        "into C++ and one write to the store",
                  io::Range::positive())
            .unit("s")
            .integer("chunk_points", 1, "points per chunk, instead of chunk_seconds", 1, 1000000000)
            .default_text("from chunk_seconds")
            .file("netcdf", "", "also write the results to this NetCDF file when the study is complete")
            .writes()
            .default_text("none");
        add_quiet_flag(p, "no progress lines (otherwise one line per second on standard error)");
      },
      run_study);
}

}  // namespace afmkit::cli
