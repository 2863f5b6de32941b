#pragma once
// One registration for every subcommand of the `afmkit` program, and the output conventions they share.
//
//   add_command(tapping, "hb", "harmonic-balance curve …",
//               [](io::ParamSet& p) { add_tapping_model_params(p); p.group("…").real(…).unit(…); },
//               run_hb);
// declares the command's parameters (TOML keys = flags), adds them as typed, grouped options, and in the callback
// resolves them (defaults < --config file < flags) and calls `run`.
//
// Outputs (docs/commands.md#outputs): a command that computes a table writes it to --output (CSV + JSON sidecar
// describing every column; empty path: no file) and prints a one-line summary, or with --json the summary as JSON
// (plus, when no file is written, the table itself: {"columns": [...], "rows": [[...], ...]}).
#include <functional>
#include <memory>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "afmkit/core/cancellation.hpp"
#include "afmkit/io/output.hpp"
#include "afmkit/io/params.hpp"
#include "afmkit/io/table.hpp"

namespace CLI {
class App;
}
namespace afmkit::impact {
class ForceLawModel;
}

namespace afmkit::cli {

/// A command's summary document made when it is read (CommandOutput::finish(ResultsMaker, ...)): it owns what it
/// needs (the computation's result), so that a caller who never reads the summary does not pay for building it.
/// Each call makes the same document.
using ResultsMaker = std::function<nlohmann::json()>;

/// What a command hands back when a program runs it rather than a person (the Python module): the summary document
/// (what --json prints, without the table), the table's columns and its rows. Nothing is printed; the table file is
/// written only when its path is given.
struct Captured {
  bool want_rows = true;  ///< false: the caller reads only results and columns (no rows kept, no history recorded)
  nlohmann::json results = nlohmann::json::object();
  /// Set: CommandOutput::finish hands the summary document to it instead of copying it into `results` (the Python
  /// module converts it to Python objects there; a copy of a large document costs as much as a short run).
  std::function<void(const nlohmann::json&)> take_results;
  /// Set: a command that makes its summary on demand (finish(ResultsMaker, ...)) hands the maker to it instead of
  /// the document (the Python module makes r.results on first access: a ~1 ms command's summary of hundreds of
  /// values costs several per cent of it, bench/command_layer.py). Commands that make their document at once give it
  /// to take_results (or `results`) as before.
  std::function<void(ResultsMaker)> take_results_maker;
  /// The table's columns: a range of io::Column (size(), [c], begin/end), shared with the command's declaration
  /// (a table declared once per unit system hands its list over without copying a string).
  io::ColumnList columns;
  nlohmann::json rows = nlohmann::json::array();
  /// Stop request of the caller (Python: Ctrl-C); the long computations check it once per point. The command line
  /// has no capture and keeps its signal handling.
  Cancellation cancellation;
  /// The table's grid (io::GridRecord::json: dims, shape, coords) when it declares one (io::TableOf::grid); else null.
  nlohmann::json grid;
  /// The parameters as run (what the sidecar records: computed defaults filled in); null until the command finishes.
  nlohmann::json parameters;
  /// The set the caller ran the command with, when it records it itself: if the command's output records this very
  /// set, CommandOutput::finish leaves `parameters` null and the caller makes the record when it needs it (the Python
  /// module: when r.params is first read; a record made per call costs a short command ~1 %,
  /// bench/command_layer.py). A command that records another set (its parameters as run, with computed values:
  /// ParamSet::record_used on a copy) still sets `parameters`.
  const io::ParamSet* record_later = nullptr;
  /// law = python: the force law the caller gave as an object (afmkit.laws.Python), built into the run's law.
  std::shared_ptr<const impact::ForceLawModel> law;
};

/// A run that computed no answer of the kind asked for: its results carry `status` other than "ok" and a `note`
/// (docs/commands.md#exit-status). The outputs are written with the status in them; on the command line finish()
/// then throws this and the program exits 1 with the note (the Python module returns the result: status in
/// r.results).
class NoAnswer : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The caller's stop request (empty on the command line).
inline Cancellation cancellation_of(const Captured* capture) { return capture ? capture->cancellation : Cancellation{}; }
/// The caller's law object (law = python; null on the command line).
inline std::shared_ptr<const impact::ForceLawModel> law_object_of(const Captured* capture) {
  return capture ? capture->law : nullptr;
}

using Declare = std::function<void(io::ParamSet&)>;
/// Runs a command on resolved parameters; `capture` is nullptr on the command line.
using Run = std::function<void(const io::ParamSet&, Captured* capture)>;

/// One leaf command: its path ("tapping orbit"), help, parameters and what it runs.
struct CommandSpec {
  std::string path;
  std::string help;
  Declare declare;
  Run run;
};

/// Every leaf command registered under `app` by register_all (commands.hpp), in registration order, for front ends
/// other than the command line (the Python module). Declared in program.cpp.
std::vector<CommandSpec> command_specs();

/// Adds subcommand `name` to `parent` (see above) and, when the root of `parent` is a Program (program.hpp), records
/// it in the program's command list; returns it.
CLI::App& add_command(CLI::App& parent, const std::string& name, const std::string& help, const Declare& declare,
                      Run run);

/// Adds a group of subcommands (`afmkit tapping …`, `afmkit control …`): one of them must be given.
CLI::App& add_command_group(CLI::App& parent, const std::string& name, const std::string& help);

/// Throws NoAnswer when `results` holds a "status" other than "ok" (its "note" in the message); commands that
/// write their outputs without a CommandOutput call it after writing them.
void require_answer(const nlohmann::json& results);

/// The "Output" group every table command has: `output` (CSV path, default `default_path`; empty: no file) and
/// the `json` flag.
void add_output_params(io::ParamSet& p, const std::string& default_path, const std::string& what);
/// The `json` flag alone (a command whose output is not a table declares it here, once for all commands).
void add_json_flag(io::ParamSet& p, const std::string& help = "print the results as JSON to standard output instead "
                                                              "of a summary line (with the table itself when no file "
                                                              "is written)");
/// The `quiet` flag of the commands that show progress on standard error.
void add_quiet_flag(io::ParamSet& p, const std::string& help = "no progress output");

/// A command's table: written to the --output file when one is given, else (with --json) kept for the printed
/// document. finish() commits the file and prints the summary.
class CommandOutput {
 public:
  /// `capture`: nullptr on the command line; else the results, columns and rows go there instead of being printed.
  CommandOutput(const io::ParamSet& params, Captured* capture, std::string command,
                const std::string& output_key = "output");
  /// It keeps a reference to `params` (the record it writes at finish()): a temporary would dangle.
  CommandOutput(io::ParamSet&& params, Captured* capture, std::string command,
                const std::string& output_key = "output") = delete;

  /// The rows of a table opened with its declaration (open(io::TableOf<Row>)): each row's cells are read by the
  /// columns' own accessors, so the values cannot go out of step with the columns.
  template <class Row>
  class Rows {
   public:
    void add(const Row& row) { add_row(row); }
    template <class Range>
    void add_all(const Range& rows) {
      for (const auto& row : rows) add(row);
    }

   private:
    friend class CommandOutput;
    Rows(CommandOutput& out, io::SharedTable<Row> table) : out_(&out), table_(std::move(table)) {}
    void add_row(const Row& row) { out_->add_row(table_.table(), row); }
    CommandOutput* out_;
    io::SharedTable<Row> table_;
  };

  /// Opens the table (file or memory) with its declared columns (io::TableOf: name, unit, description and the
  /// value of each in a row); call once, then add rows through the handle returned. A table declared as a grid
  /// (io::TableOf::grid) is recorded as such (the sidecar's and the capture's "grid").
  template <class Row>
  [[nodiscard]] Rows<Row> open(io::TableOf<Row> table) {
    return open(io::SharedTable<Row>(std::move(table)));
  }
  /// The same with a declaration made once and shared (io::SharedTable: a table declared once per unit system): its
  /// columns are handed over without copying them.
  template <class Row>
  [[nodiscard]] Rows<Row> open(io::SharedTable<Row> shared) {
    open_columns(shared.columns());
    const io::TableOf<Row>& table = shared.table();
    if (!table.grid().empty()) {
      grid_ = io::GridRecord(table.grid());
      for (const io::GridDimension& d : table.grid()) {
        const auto& entries = table.entries();
        for (std::size_t c = 0; c < entries.size(); ++c)
          if (entries[c].column.name == d.column) grid_columns_.push_back(c);
      }
    }
    return Rows<Row>(*this, std::move(shared));
  }
  /// Opens the table (file or memory) with its columns; call once before adding rows with row().
  void open(std::vector<io::Column> columns);
  /// Adds one row; cells as io::TableWriter::row.
  template <class... Cells>
  void row(const Cells&... cells) {
    if (file_) file_->row(cells...);
    if (keep_rows_) rows_.push_back(nlohmann::json::array({nlohmann::json(cell_value(cells))...}));
    ++count_;
  }
  std::size_t rows() const { return count_; }
  const std::string& path() const& { return path_; }
  bool writes_file() const { return !path_.empty(); }
  /// The rows are wanted (a file, a capture, or --json without a file): commands skip recording a history nobody
  /// will read.
  bool keeps_rows() const { return writes_file() || keep_rows_; }
  /// The rows are held in memory (--json without a file, or a capture that wants them): their memory grows with them.
  bool holds_rows() const { return keep_rows_; }

  /// The other files of the command's result (images, a series, a point cloud): staged there, they are committed
  /// with the table by finish(), all of them or none (io::OutputSet).
  io::OutputSet& outputs() & { return outputs_; }

  /// Commits the file with the sidecar (parameters, `results`, columns) and the files of outputs(), as one set.
  /// Then prints `results` as JSON (--json; with the rows when no file was written), or `summary` (if not empty) and
  /// where the table went. When `results` has a "status" other than "ok", throws NoAnswer with its "note"
  /// afterwards (command line only).
  void finish(const nlohmann::json& results, const std::string& summary);
  /// The same with the summary made by `make_results` where it is read: at once for the files, the standard output
  /// and a capture without take_results_maker (the same outputs as finish(make_results(), summary)); handed to the
  /// capture's take_results_maker otherwise (not made unless the caller reads it).
  void finish(ResultsMaker make_results, const std::string& summary);

 private:
  template <class Row>
  void add_row(const io::TableOf<Row>& table, const Row& row) {
    nlohmann::json cells = keep_rows_ ? nlohmann::json::array() : nlohmann::json();
    const auto& entries = table.entries();
    if (keep_rows_) cells.get_ref<nlohmann::json::array_t&>().reserve(entries.size());
    for (std::size_t c = 0; c < entries.size(); ++c) {
      const io::Cell cell = entries[c].value(row);
      if (file_) io::write_cell(*file_, cell);
      if (keep_rows_) cells.push_back(io::cell_json(cell));
      for (std::size_t d = 0; d < grid_columns_.size(); ++d)
        if (grid_columns_[d] == c) grid_.value(d, grid_coordinate(cell));
    }
    if (file_) file_->end_row();
    if (keep_rows_) rows_.push_back(std::move(cells));
    if (!grid_.empty()) grid_.end_row();
    ++count_;
  }
  static double grid_coordinate(const io::Cell& cell) {
    if (const double* x = std::get_if<double>(&cell)) return *x;
    if (const long* n = std::get_if<long>(&cell)) return static_cast<double>(*n);
    throw std::logic_error("a grid dimension's column must hold numbers");
  }
  void open_columns(io::ColumnList columns);
  template <class T>
  static auto cell_value(const T& v) {
    if constexpr (std::is_convertible_v<T, std::string_view> && !std::is_arithmetic_v<T>) return std::string(v);
    else return v;
  }
  const io::ParamSet& params_;
  Captured* capture_ = nullptr;
  std::string command_;
  std::string path_;
  bool json_ = false;
  bool keep_rows_ = false;
  io::ColumnList columns_;
  io::GridRecord grid_;                    // of a table declared as a grid (else empty)
  std::vector<std::size_t> grid_columns_;  // the column of each grid dimension
  std::optional<io::TableWriter> file_;
  io::OutputSet outputs_;
  nlohmann::json rows_ = nlohmann::json::array();
  std::size_t count_ = 0;
};

}  // namespace afmkit::cli
