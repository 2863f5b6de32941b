// Recorded spiral CSV reader (format, rules and messages in include/afmkit/scan/recorded_spiral.hpp).
//
// Structure: read_row() turns the next data line into a validated Row (cells, time, sampling, radius, index
// value); the angle mode unwraps row by row and needs no look-ahead after the first revolution (buffered by the
// constructor to measure Ω); the index mode buffers one revolution — the rows from one rising edge to the next —
// because their angles are known only once the closing edge is seen. The buffer and the line keep their capacity,
// so the per-sample path allocates nothing once the first revolution has been read.
#include "afmkit/scan/recorded_spiral.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "afmkit/core/numbers.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"
#include "afmkit/io/number.hpp"
#include "file_bytes.hpp"

namespace afmkit::scan {

namespace {

using afmkit::numbers::two_pi;
using std::numbers::pi;
constexpr std::size_t max_line_bytes = std::size_t{1} << 20;
constexpr std::size_t max_revolution_samples = std::size_t{1} << 24;
constexpr double sampling_tolerance = 1e-3;  // |Δt − Δt0| <= 1e-3 · Δt0
using afmkit::numbers::nan;

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

bool same_name(std::string_view cell, std::string_view name) {
  if (cell.size() != name.size()) return false;
  for (std::size_t k = 0; k < name.size(); ++k) {
    char c = cell[k];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != name[k]) return false;
  }
  return true;
}

constexpr double kMaxDeflection = 1.0;  // [m]: every recorded deflection lies in [−1, 1] m

enum Column { time_column, radius_column, deflection_column, angle_column, index_column, column_count };
constexpr const char* column_names[column_count] = {"time", "radius", "deflection", "angle", "index"};

}  // namespace

struct RecordedSpiralReader::State {
  // One data line: the used cells, parsed and checked. `value` is the raw angle or the index value.
  struct Row {
    double time, value, radius, deflection;
  };

  std::unique_ptr<std::istream> in;
  std::string origin;
  std::string text;  // the current line
  long line = 0;     // lines read so far (the current line's number)
  std::string failure;  // message of the first InputError: the reader stays failed

  // Header.
  long header_line = 0;
  long columns = 0;                     // cells per row
  long position[column_count] = {-1, -1, -1, -1, -1};  // 0-based cell of each known column, -1 when absent
  bool index_mode = false;

  // Row checks.
  long rows = 0;  // data rows read
  long last_row_line = 0;
  double previous_time = nan, first_interval = nan;
  long previous_time_line = 0, first_interval_line = 0;

  // Angle mode.
  double previous_raw = nan, unwrap_offset = 0.0, previous_angle = nan, first_angle = nan;
  // Index mode.
  int previous_index = -1;  // -1: no row yet
  long edges = 0;           // rising edges seen
  double edge_time = nan;   // time of the latest edge (angle 2π · (edges − 1))
  SpiralSample pending{};   // the latest edge's sample: first of the next revolution

  std::vector<SpiralSample> buffer;  // look-ahead (one revolution)
  std::size_t cursor = 0;
  bool finished = false;  // the end of the data was reached and checked
  long dropped = 0;
  double sample_rate = nan, rotation_frequency = nan;

  [[noreturn]] void fail(const std::string& message, long at_line) const {
    throw InputError(fmt::format("{}:{}: {}", origin, at_line, message));
  }
  [[noreturn]] void fail(const std::string& message) const { fail(message, line); }
  [[noreturn]] void fail_column(Column c, const std::string& message) const {
    fail(fmt::format("column '{}': {}", column_names[c], message));
  }

  /// The next line into `text` (without its '\n'); false at the end of the input.
  bool read_line() {
    text.clear();
    std::streambuf* buf = in->rdbuf();
    using traits = std::char_traits<char>;
    bool any = false;
    for (;;) {
      const traits::int_type c = buf->sbumpc();
      if (traits::eq_int_type(c, traits::eof())) break;
      any = true;
      if (traits::to_char_type(c) == '\n') break;
      if (text.size() >= max_line_bytes) {
        ++line;
        fail(fmt::format("line longer than {} bytes (not a recorded spiral CSV?)", max_line_bytes));
      }
      text.push_back(traits::to_char_type(c));
    }
    if (!any) return false;
    ++line;
    if (line == 1 && std::string_view(text).substr(0, 3) == "\xEF\xBB\xBF") text.erase(0, 3);
    return true;
  }

  /// The next line that is not blank or a comment; false at the end of the input.
  bool read_content_line() {
    while (read_line()) {
      const std::string_view t = trimmed(text);
      if (!t.empty() && t.front() != '#') return true;
    }
    return false;
  }

  void read_header() {
    if (!read_content_line())
      throw InputError(fmt::format("{}: no header line: a recorded spiral starts with a line naming its columns "
                                   "(time, radius, deflection and angle or index)",
                                   origin));
    header_line = line;
    std::string_view rest = text;
    long numbers = 0;
    for (long cell = 0;; ++cell) {
      const std::size_t comma = rest.find(',');
      const std::string_view name = trimmed(rest.substr(0, comma));
      if (io::parse_real(name)) ++numbers;
      for (int c = 0; c < column_count; ++c) {
        if (!same_name(name, column_names[c])) continue;
        if (position[c] >= 0)
          fail(fmt::format("duplicate column '{}' (columns {} and {} of the header)", column_names[c],
                           position[c] + 1, cell + 1));
        position[c] = cell;
      }
      columns = cell + 1;
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
    if (numbers == columns)
      fail("the first line holds numbers, not column names: a recorded spiral starts with a header line such as "
           "'time,angle,radius,deflection'");
    for (Column c : {time_column, radius_column, deflection_column})
      if (position[c] < 0)
        fail(fmt::format("missing column '{}' (the header must name time, radius, deflection and one of angle / "
                         "index)",
                         column_names[c]));
    if (position[angle_column] >= 0 && position[index_column] >= 0)
      fail(fmt::format("both an 'angle' column ({}) and an 'index' column ({}): give exactly one",
                       position[angle_column] + 1, position[index_column] + 1));
    if (position[angle_column] < 0 && position[index_column] < 0)
      fail("neither an 'angle' nor an 'index' column: give exactly one (angle [rad] or index pulse 0/1)");
    index_mode = position[index_column] >= 0;
  }

  double number(Column c, std::string_view cell) const {
    cell = trimmed(cell);
    if (cell.empty()) fail_column(c, "empty cell");
    const auto v = io::parse_real(cell);
    if (!v || !std::isfinite(*v)) fail_column(c, fmt::format("{} is not a finite number", detail::shown(cell)));
    return *v;
  }

  /// The next data row, validated; false at the end of the input.
  bool read_row(Row& row) {
    if (!read_content_line()) return false;
    long cells = 1;
    for (char ch : text) cells += ch == ',' ? 1 : 0;
    if (cells != columns)
      fail(fmt::format("ragged row: {} cell{}, the header (line {}) names {} column{}", cells, cells == 1 ? "" : "s",
                       header_line, columns, columns == 1 ? "" : "s"));
    const Column value_column = index_mode ? index_column : angle_column;
    std::string_view rest = text;
    for (long cell = 0; cell < columns; ++cell) {
      const std::size_t comma = rest.find(',');
      const std::string_view content = rest.substr(0, comma);
      if (cell == position[time_column]) row.time = number(time_column, content);
      if (cell == position[radius_column]) row.radius = number(radius_column, content);
      if (cell == position[deflection_column]) row.deflection = number(deflection_column, content);
      if (cell == position[value_column]) row.value = number(value_column, content);
      if (comma != std::string_view::npos) rest.remove_prefix(comma + 1);
    }
    check_time(row.time);
    // a deflection beyond ±1 m is no AFM signal, and near the double range it overflows the filter's sums
    // (docs/scan.md#recorded-data: the same bound as the sample heights)
    if (!(std::abs(row.deflection) <= kMaxDeflection))
      fail_column(deflection_column, fmt::format("{} m is out of range: a recorded deflection must lie in [-{}, {}] m",
                                                 row.deflection, kMaxDeflection, kMaxDeflection));
    if (row.radius < 0)
      fail_column(radius_column, fmt::format("{} m is negative (the distance from the spindle axis is >= 0)",
                                             row.radius));
    if (index_mode && row.value != 0.0 && row.value != 1.0)
      fail_column(index_column, fmt::format("{} is not 0 or 1 (the index pulse is a logic level)", row.value));
    ++rows;
    last_row_line = line;
    return true;
  }

  void check_time(double t) {
    if (rows >= 1) {
      const double dt = t - previous_time;
      if (!(dt > 0))
        fail_column(time_column, fmt::format("{} s is not after the previous sample's {} s (line {}): time must "
                                             "increase strictly",
                                             t, previous_time, previous_time_line));
      if (rows == 1) {
        first_interval = dt;
        first_interval_line = line;
        sample_rate = 1.0 / dt;
        if (!std::isfinite(dt) || !std::isfinite(sample_rate) || !(sample_rate > 0))
          fail_column(time_column, fmt::format("the first sampling interval {} s gives no finite sample rate", dt));
      } else if (!(std::abs(dt - first_interval) <= sampling_tolerance * first_interval)) {
        fail_column(time_column,
                    fmt::format("non-uniform sampling: the interval {} s from line {} differs from the first "
                                "interval {} s (line {}) by more than 0.1 %",
                                dt, previous_time_line, first_interval, first_interval_line));
      }
    }
    previous_time = t;
    previous_time_line = line;
  }

  /// Angle mode: the unwrapped angle of `raw` (the current row's angle cell).
  double unwrap(double raw) {
    double angle = raw;
    if (rows == 1) {
      first_angle = raw;
    } else {
      if (raw - previous_raw < -pi) unwrap_offset += two_pi;  // a wrap
      angle = raw + unwrap_offset;
      if (!(angle > previous_angle))
        fail_column(angle_column,
                    fmt::format("the spindle goes backwards or stands still: {} rad after {} rad on the previous "
                                "sample, {} rad after {} rad unwrapped (a step below -pi counts as one wrap)",
                                raw, previous_raw, angle, previous_angle));
    }
    previous_raw = raw;
    previous_angle = angle;
    return angle;
  }

  /// Index mode: whether the current row (index `value`) is a rising edge.
  bool rising_edge(double value) {
    const int level = value == 1.0 ? 1 : 0;
    const bool edge = previous_index == 0 && level == 1;
    previous_index = level;
    return edge;
  }

  void check_look_ahead() const {
    if (buffer.size() >= max_revolution_samples)
      fail_column(index_mode ? index_column : angle_column,
                  fmt::format("a revolution longer than {} samples (the reader's look-ahead limit)",
                              max_revolution_samples));
  }

  [[noreturn]] void fail_too_short(double revolutions) const {
    if (rows == 0)
      fail("no data rows after the header: a recorded spiral needs at least two revolutions", header_line);
    const Column c = index_mode ? index_column : angle_column;
    const std::string what = index_mode ? fmt::format("{} index edge{}", edges, edges == 1 ? "" : "s")
                                        : fmt::format("{:.3f} revolutions", revolutions);
    fail(fmt::format("column '{}': the data end after {}: a recorded spiral needs at least two revolutions{}",
                     column_names[c], what, index_mode ? " (three index edges)" : ""),
         last_row_line > 0 ? last_row_line : line);
  }

  // ---- angle mode ----

  void start_angle_mode() {
    Row row{};
    double crossing_time = nan;
    while (read_row(row)) {
      const double angle = unwrap(row.value);
      check_look_ahead();
      buffer.push_back({row.time, angle, row.radius, row.deflection});
      const double target = first_angle + two_pi;
      if (buffer.size() >= 2 && angle >= target) {
        const SpiralSample& before = buffer[buffer.size() - 2];
        crossing_time = before.time + (target - before.angle) * (row.time - before.time) / (angle - before.angle);
        break;
      }
    }
    if (std::isnan(crossing_time)) fail_too_short((previous_angle - first_angle) / two_pi);
    rotation_frequency = two_pi / (crossing_time - buffer.front().time);
    if (!std::isfinite(rotation_frequency) || !(rotation_frequency > 0))
      fail_column(angle_column, fmt::format("the first revolution gives no finite rotation frequency ({} rad/s)",
                                            rotation_frequency));
  }

  bool next_angle_mode(SpiralSample& sample) {
    if (cursor < buffer.size()) {
      sample = buffer[cursor++];
      return true;
    }
    if (finished) return false;
    Row row{};
    if (!read_row(row)) {
      if (previous_angle - first_angle < 2 * two_pi) fail_too_short((previous_angle - first_angle) / two_pi);
      finished = true;
      return false;
    }
    sample = {row.time, unwrap(row.value), row.radius, row.deflection};
    return true;
  }

  // ---- index mode ----

  /// Angles of buffer[from …] (revolution `revolution`, from the edge at edge_time to the edge at `next_edge`).
  void fill_angles(std::size_t from, long revolution, double next_edge_time) {
    const double base = two_pi * static_cast<double>(revolution);
    const double period = next_edge_time - edge_time;
    double previous = from > 0 ? buffer[from - 1].angle : -std::numeric_limits<double>::infinity();
    for (std::size_t k = from; k < buffer.size(); ++k) {
      const double angle = base + two_pi * ((buffer[k].time - edge_time) / period);
      if (!(angle > previous))
        fail_column(index_column, "angles of successive samples round to the same value (too many samples per "
                                  "revolution or revolutions for double precision)");
      buffer[k].angle = previous = angle;
    }
    if (!(base + two_pi > previous))
      fail_column(index_column, "angles of successive samples round to the same value");
  }

  /// Reads rows into the buffer up to the next rising edge (which becomes `pending`, angle 2π · edges); false at
  /// the end of the input. Rows before the first edge are only counted as dropped.
  bool read_to_edge() {
    Row row{};
    while (read_row(row)) {
      if (rising_edge(row.value)) {
        const double time = row.time;
        if (edges >= 1) fill_angles(1, edges - 1, time);
        pending = {time, two_pi * static_cast<double>(edges), row.radius, row.deflection};
        ++edges;
        edge_time = time;
        return true;
      }
      if (edges == 0) {
        ++dropped;
      } else {
        check_look_ahead();
        buffer.push_back({row.time, 0.0, row.radius, row.deflection});
      }
    }
    return false;
  }

  void start_index_mode() {
    if (!read_to_edge()) fail_too_short(0);  // first edge
    buffer.push_back(pending);
    const double first_edge = edge_time;
    if (!read_to_edge()) fail_too_short(0);  // second edge: the first revolution is buffered
    rotation_frequency = two_pi / (edge_time - first_edge);
    if (!std::isfinite(rotation_frequency) || !(rotation_frequency > 0))
      fail_column(index_column, fmt::format("the first revolution gives no finite rotation frequency ({} rad/s)",
                                            rotation_frequency));
  }

  bool next_index_mode(SpiralSample& sample) {
    if (cursor < buffer.size()) {
      sample = buffer[cursor++];
      return true;
    }
    if (finished) return false;
    buffer.clear();
    cursor = 0;
    buffer.push_back(pending);
    if (!read_to_edge()) {
      dropped += static_cast<long>(buffer.size()) - 1;  // after the last edge
      buffer.resize(1);                                   // the last edge's own sample is kept
      if (edges < 3) fail_too_short(0);
      finished = true;
    }
    sample = buffer[cursor++];
    return true;
  }
};

RecordedSpiralReader::RecordedSpiralReader(const std::string& path) {
  *this = RecordedSpiralReader(files::open_input_file(path, "recorded spiral"), path);
}

RecordedSpiralReader::RecordedSpiralReader(std::unique_ptr<std::istream> in, std::string origin)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.origin = std::move(origin);
  if (!in || !in->rdbuf()) throw InputError(fmt::format("{}: no input stream", s.origin));
  s.in = std::move(in);
  s.read_header();
  if (s.index_mode)
    s.start_index_mode();
  else
    s.start_angle_mode();
}

RecordedSpiralReader::~RecordedSpiralReader() = default;
RecordedSpiralReader::RecordedSpiralReader(RecordedSpiralReader&&) noexcept = default;
RecordedSpiralReader& RecordedSpiralReader::operator=(RecordedSpiralReader&&) noexcept = default;

bool RecordedSpiralReader::next(SpiralSample& sample) {
  State& s = *state_;
  if (!s.failure.empty()) throw InputError(s.failure);
  try {
    return s.index_mode ? s.next_index_mode(sample) : s.next_angle_mode(sample);
  } catch (const InputError& e) {
    s.failure = e.what();
    throw;
  }
}

double RecordedSpiralReader::sample_rate() const { return state_->sample_rate; }
double RecordedSpiralReader::rotation_frequency() const { return state_->rotation_frequency; }
long RecordedSpiralReader::dropped_samples() const { return state_->dropped; }
bool RecordedSpiralReader::uses_index_pulse() const { return state_->index_mode; }

}  // namespace afmkit::scan
