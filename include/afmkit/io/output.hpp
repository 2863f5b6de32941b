#pragma once
// Output files: CSV tables with a header row and a JSON sidecar (<file>.json) holding the command, the
// parameters, the afmkit version and summary results. Tables are streamed: each row is formatted into a small
// buffer and appended to a temporary file next to the target; commit() renames it into place (atomic), so a
// failed or interrupted run never leaves a half-written output and memory stays bounded by a buffer, not the
// file. Each writer has its own temporary, `<target>.tmp.<pid>.<host>.<random>` (unique per writer: threads and
// processes writing the same output never share one; a later run on the same host removes those of a process
// that no longer exists, e.g. one killed by SIGKILL). Several files of one result (a table and its sidecar, the
// images of a scan) are committed as a set (OutputSet): all of them or none. Every column has a unit and a description, listed in the sidecar's "columns" array (docs/units.md).
// Undefined values: `nan` in CSV, `null` in JSON; infinite values: `inf`/`-inf` in CSV, "inf"/"-inf" in JSON
// (docs/conventions.md#undefined-values).
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "afmkit/io/params.hpp"

namespace afmkit::io {

/// One column of a table: its CSV header name, its unit (docs/units.md: "nm", "rad", "dimensionless", …) and
/// what it holds. The sidecar lists them in order as {"name", "unit", "description"}.
struct Column {
  std::string name;
  std::string unit;
  std::string description;
};

/// The sidecar's "columns" array for `columns`.
nlohmann::json columns_json(const std::vector<Column>& columns);

/// `value` with afmkit's one convention for non-finite numbers in JSON: NaN (not defined) becomes null, ±infinity
/// the strings "inf" / "-inf" (nlohmann would write both as null). Applied to every sidecar and printed document.
nlohmann::json finite_json(nlohmann::json value);
/// `finite_json(value)` as indented text (what sidecars and `--json` print).
std::string json_text(const nlohmann::json& value);
/// The same, consuming `value` (no copy of a large document).
std::string json_text(nlohmann::json&& value);

/// Files committed together: each is written completely to its own temporary beside its target first (add, or a
/// TableWriter's stage), then commit() moves them all into place with SIGINT/SIGTERM/SIGHUP held back and the
/// target folders locked against other afmkit processes committing there (flock), so that two runs writing the
/// same outputs leave the files of one run, never a mix; if a move fails, the files already moved are put back
/// (the old file, or none) and InputError says why. Temporaries not committed are removed at destruction.
class OutputSet {
 public:
  OutputSet() = default;
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// Writes `content` to a temporary for `path` now (a symbolic link is followed; a path that exists and is not a
  /// regular file is refused). InputError naming the file and the reason on failure.
  void add(const std::string& path, const std::string& content);
  /// Moves every file added into place (see above); the set is empty afterwards.
  void commit();
  std::size_t size() const { return staged_.size(); }

  struct Staged {  // (public for the writer in output.cpp; not an interface)
    std::string path, target, temporary;
    int slot = -1;
  };
  /// Takes a complete temporary written by a writer of output.cpp.
  void adopt(Staged staged) { staged_.push_back(std::move(staged)); }

 private:
  std::vector<Staged> staged_;
  void discard() noexcept;
};

/// Streams a column-named CSV table to `path` atomically. Cells are numbers (shortest round-trip text),
/// integers, strings or booleans (0/1); a string holding a comma, a double quote or a line break is quoted as in
/// RFC 4180 ("a,b" -> "\"a,b\"", a quote doubled). Usage:
///   TableWriter out(path, {{"separation", "nm", "separation l"}, {"amplitude", "nm", "amplitude A"}});
///   for (...) out.row(l, B);
///   out.commit(make_sidecar(...));     // rename into place, then write the sidecar (with "columns" added)
/// A writer destroyed without commit() removes its temporary file.
class TableWriter {
 public:
  /// Opens its own temporary beside `path` (creating parent folders). Throws afmkit::InputError when that is impossible, and
  /// std::logic_error when a column has an empty name, unit or description (a programming error).
  TableWriter(std::string path, std::vector<Column> columns);
  ~TableWriter();
  TableWriter(const TableWriter&) = delete;
  TableWriter& operator=(const TableWriter&) = delete;

  TableWriter& cell(double value);
  TableWriter& cell(long value);
  TableWriter& cell(int value) { return cell(static_cast<long>(value)); }
  TableWriter& cell(std::size_t value) { return cell(static_cast<long>(value)); }
  TableWriter& cell(bool value);
  TableWriter& cell(std::string_view text);
  TableWriter& cell(const char* text) { return cell(std::string_view(text)); }
  TableWriter& cell(const std::string& text) { return cell(std::string_view(text)); }
  /// Ends the current row; throws std::logic_error when its cell count differs from the column count.
  void end_row();
  /// One whole row.
  template <class... Cells>
  void row(const Cells&... cells) {
    (cell(cells), ...);
    end_row();
  }

  /// Flushes, renames the table into place and writes `<path>.json` (atomically): `sidecar` with the "columns"
  /// array added. Throws InputError on an I/O failure (nothing is left behind then).
  void commit(const nlohmann::json& sidecar);
  /// The same, but the table and its sidecar join `set`, moved into place by set.commit() with the other files
  /// of the result.
  void stage(const nlohmann::json& sidecar, OutputSet& set);

  const std::vector<Column>& columns() const& { return columns_; }
  std::vector<Column> columns() const&& { return columns_; }
  std::size_t size() const { return rows_; }  ///< rows written so far
  const std::string& path() const& { return path_; }
  std::string path() const&& { return path_; }

 private:
  std::string path_;
  std::string target_;  // path_, or the file its symbolic link points to
  std::string temporary_;
  int slot_ = -1;       // registration for removal on a signal
  std::vector<Column> columns_;
  std::FILE* file_ = nullptr;
  fmt::memory_buffer buffer_;
  std::size_t rows_ = 0;
  std::size_t cells_in_row_ = 0;
  bool committed_ = false;

  void separator();
  void flush();
  void discard() noexcept;
};

/// Write `content` to `path` atomically; creates parent directories. Throws afmkit::InputError on failure.
/// Outputs (tables, sidecars, files): written to their own temporary, synced, then renamed; a symbolic link is
/// followed (its target is replaced); a path that exists but is not a regular file is refused (InputError). The
/// reason of a failure is named ("No space left on device", "Read-only file system").
void write_file_atomic(const std::string& path, const std::string& content);

/// Refuses, before anything is computed and without creating anything, an output that could not be created in the
/// folder `dir`: that folder, or its nearest ancestor that exists (where it would be created), must be a writable
/// folder. InvalidParameter naming `parameter`: "<parameter> '<shown>' cannot be written: <why>: must be a
/// writable folder" (`shown`: the path the user gave).
void require_writable_folder(const std::string& parameter, const std::string& shown, const std::string& dir);

/// Installs SIGINT/SIGTERM/SIGHUP handlers that remove the temporaries of outputs being written, then end the
/// process by the same signal (the command-line program calls it once at start).
void remove_temporaries_on_signal();

/// Metadata of a run, written as the sidecar `<csv path>.json`: program, version, command, parameters (their
/// values as given), parameter_units (when given: key -> unit), results; TableWriter::commit adds "columns".
nlohmann::json make_sidecar(const std::string& command, const nlohmann::json& parameters,
                            const nlohmann::json& results = nlohmann::json::object(),
                            const nlohmann::json& parameter_units = nlohmann::json::object());
/// The same from a command's parameter set (values and units).
nlohmann::json make_sidecar(const std::string& command, const ParamSet& parameters,
                            const nlohmann::json& results = nlohmann::json::object());

}  // namespace afmkit::io
