#include "text_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "text_presets.hpp"
#include "text_table.hpp"
#include "units.hpp"

namespace afmkit::io::curves::detail {

namespace {

// A header cell split into its name and unit: "Height (nm)", "Defl [V]", "Calc_Ramp_Ex_nm" (the unit among the
// '_'-separated words: "Defl_nm_Ex" -> "Defl_Ex", "nm"), "Height/nm", "Z-Sense(nm)"; no unit: "Height".
struct HeaderCell {
  std::string name;
  std::string unit;
  std::string raw;
};

HeaderCell parse_header_cell(std::string_view raw) {
  HeaderCell cell;
  std::string_view t = trim(raw);
  if (t.size() >= 2 && (t.front() == '"' || t.front() == '\'') && t.back() == t.front()) t = trim(t.substr(1, t.size() - 2));
  cell.raw = std::string(t);
  if (!t.empty() && (t.back() == ')' || t.back() == ']')) {
    const char open = t.back() == ')' ? '(' : '[';
    const std::size_t at = t.rfind(open);
    if (at != std::string_view::npos) {
      cell.unit = std::string(trim(t.substr(at + 1, t.size() - at - 2)));
      std::string_view name = trim(t.substr(0, at));
      while (!name.empty() && (name.back() == ',' || name.back() == ':' || name.back() == '/')) name.remove_suffix(1);
      cell.name = std::string(trim(name));
      return cell;
    }
  }
  if (const std::size_t slash = t.rfind('/'); slash != std::string_view::npos && slash + 1 < t.size() &&
                                                parse_unit(trim(t.substr(slash + 1)))) {
    cell.unit = std::string(trim(t.substr(slash + 1)));
    cell.name = std::string(trim(t.substr(0, slash)));
    return cell;
  }
  if (t.find('_') != std::string_view::npos) {
    std::vector<std::string_view> words;
    std::size_t start = 0;
    while (true) {
      const std::size_t at = t.find('_', start);
      words.push_back(t.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
      if (at == std::string_view::npos) break;
      start = at + 1;
    }
    for (std::size_t i = words.size(); i-- > 1;) {  // the first word is the name's
      if (parse_unit(words[i])) {
        cell.unit = std::string(words[i]);
        for (std::size_t j = 0; j < words.size(); ++j) {
          if (j == i) continue;
          if (!cell.name.empty()) cell.name += '_';
          cell.name += words[j];
        }
        return cell;
      }
    }
  }
  cell.name = std::string(t);
  return cell;
}

bool matches(const Candidate& cand, const HeaderCell& cell) {
  const std::string name = lower(cell.name);
  const std::string raw = lower(cell.raw);
  const std::string pattern = lower(cand.pattern);
  if (!pattern.empty() && pattern.front() == '*') {
    const std::string_view suffix = std::string_view(pattern).substr(1);
    return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  }
  if (!pattern.empty() && pattern.front() == '~') return name.find(pattern.substr(1)) != std::string::npos;
  return name == pattern || raw == pattern;
}

// A column chosen for one role, with its unit.
struct Column {
  int index = -1;  // 0-based; -1: not used
  Unit unit{Quantity::length, 1.0};
  std::string label;  // for messages: "column 2 ('Defl (V)')"
};

std::string describe_header(const std::vector<HeaderCell>& cells) {
  std::string out;
  for (std::size_t i = 0; i < cells.size() && i < 12; ++i) {
    if (!out.empty()) out += ", ";
    out += fmt::format("{} '{}'", i + 1, cells[i].raw);
  }
  if (cells.size() > 12) out += ", ...";
  return out;
}

bool quantity_allowed(const Role& role, Quantity q) {
  return std::find(role.quantities.begin(), role.quantities.end(), q) != role.quantities.end();
}

std::string allowed_quantities(const Role& role) {
  std::string out;
  for (Quantity q : role.quantities) {
    if (!out.empty()) out += " or ";
    out += to_string(q);
  }
  return out;
}

Column resolve(const Role& role, const ColumnChoice& user, const std::vector<HeaderCell>& header, int header_line,
               std::size_t ncol, const std::string& origin, const std::string& format) {
  Column col;
  std::string header_unit;
  std::string default_unit;
  if (user.position > 0) {
    if (static_cast<std::size_t>(user.position) > ncol)
      throw InputError(fmt::format("{}: the {} column is {}, but the file has {} column{}", origin, role.name,
                                   user.position, ncol, ncol == 1 ? "" : "s"));
    col.index = user.position - 1;
  } else if (!user.name.empty()) {
    const Candidate wanted{user.name, ""};
    for (std::size_t i = 0; i < header.size() && col.index < 0; ++i)
      if (matches(wanted, header[i])) col.index = static_cast<int>(i);
    if (col.index < 0)
      throw InputError(header.empty()
                           ? fmt::format("{}: the {} column '{}' is chosen by name, but the file has no header row "
                                         "(choose it by position)",
                                         origin, role.name, user.name)
                           : fmt::format("{}: no column named '{}' for the {} (header, line {}: {})", origin,
                                         user.name, role.name, header_line, describe_header(header)));
  } else {
    for (const Candidate& cand : role.candidates) {
      for (std::size_t i = 0; i < header.size() && col.index < 0; ++i)
        if (matches(cand, header[i])) {
          col.index = static_cast<int>(i);
          default_unit = cand.unit;
        }
      if (col.index >= 0) break;
    }
    if (col.index < 0 && header.empty() && role.default_position > 0 &&
        static_cast<std::size_t>(role.default_position) <= ncol) {
      col.index = role.default_position - 1;
      default_unit = role.default_unit;
    }
    if (col.index < 0) {
      if (!role.required) return col;
      if (header.empty())
        throw InputError(fmt::format("{}: the {} preset needs a {} column, and the file (with {} column{}, no "
                                     "header row) has none: choose it by position",
                                     origin, format, role.name, ncol, ncol == 1 ? "" : "s"));
      throw InputError(fmt::format("{}: no {} column in the header (line {}: {}){}", origin, role.name, header_line,
                                   describe_header(header),
                                   role.expected.empty() ? std::string(": choose it by name or position")
                                                         : fmt::format(": the {} preset expects {}", format,
                                                                       role.expected)));
    }
  }
  if (role.quantities.empty()) return col;  // a segment column: numbers without unit
  if (static_cast<std::size_t>(col.index) < header.size()) {
    header_unit = header[static_cast<std::size_t>(col.index)].unit;
    col.label = fmt::format("column {} ('{}', line {})", col.index + 1, header[static_cast<std::size_t>(col.index)].raw,
                            header_line);
  } else {
    col.label = fmt::format("column {}", col.index + 1);
  }
  std::string unit = !user.unit.empty() ? user.unit : !header_unit.empty() ? header_unit : default_unit;
  if (unit.empty())
    throw InputError(fmt::format("{}: the {} {} has no unit{}: give it in the read options ({} unit; one of {})",
                                 origin, role.name, col.label, header.empty() ? " (no header row)" : " in its header",
                                 role.name, known_units()));
  const auto parsed = parse_unit(unit);
  if (!parsed)
    throw InputError(fmt::format("{}: the {} {}: unknown unit '{}' (known: {})", origin, role.name, col.label, unit,
                                 known_units()));
  if (!quantity_allowed(role, parsed->quantity))
    throw InputError(fmt::format("{}: the {} {}: the unit '{}' is a {}, the {} must be a {}", origin, role.name,
                                 col.label, unit, to_string(parsed->quantity), role.name, allowed_quantities(role)));
  col.unit = *parsed;
  return col;
}

// Metadata "key: value" (or "key=value", "key<TAB>value"): the number after the first ':' / '=' that is followed
// by one.
std::optional<double> metadata_value(std::string_view text, std::string_view key) {
  const std::string l = lower(text);
  const std::string k = lower(key);
  if (l.compare(0, k.size(), k) != 0) return std::nullopt;
  std::string_view rest = std::string_view(text).substr(k.size());
  rest = trim(rest);
  if (rest.empty() || (rest.front() != ':' && rest.front() != '=')) return std::nullopt;
  rest = trim(rest.substr(1));
  double v;
  if (!parse_cell(rest, false, v) && !parse_cell(rest, true, v)) return std::nullopt;
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

void read_metadata(const Preset& preset, const std::vector<TextLine>& lines, CurveMetadata& meta,
                   std::vector<std::string>& notes, const std::string& origin) {
  for (const TextLine& line : lines) {
    for (const MetadataKey& key : preset.metadata) {
      const auto v = metadata_value(line.text, key.key);
      if (!v) continue;
      if (key.ignore_value && *v == *key.ignore_value) {
        notes.push_back(fmt::format("line {}: '{}' is the instrument's default {}, not a calibration: ignored",
                                    line.line, line.text, key.key));
        continue;
      }
      const double si = key.reciprocal ? 1.0 / (*v * key.scale) : *v * key.scale;
      if (!(std::isfinite(si) && si > 0))
        throw InputError(fmt::format("{}: line {}: '{}': the {} must be positive and finite", origin, line.line,
                                     line.text, key.target == MetadataKey::spring_constant ? "spring constant"
                                                                                           : "InvOLS"));
      (key.target == MetadataKey::spring_constant ? meta.spring_constant : meta.invols) = si;
    }
  }
}

SegmentKind kind_from_label(std::string_view label) {
  const std::string l = lower(trim(label));
  if (l.find("extend") != std::string::npos || l.find("approach") != std::string::npos) return SegmentKind::approach;
  if (l.find("retract") != std::string::npos) return SegmentKind::retract;
  if (l.find("pause") != std::string::npos) return SegmentKind::pause;
  return SegmentKind::unknown;
}

SegmentKind kind_from_height(const std::vector<double>& h) {
  if (h.size() < 2) return SegmentKind::unknown;
  const double dz = h.back() - h.front();
  if (dz < 0) return SegmentKind::approach;  // towards the sample: height decreasing
  if (dz > 0) return SegmentKind::retract;
  return SegmentKind::pause;
}

// The channels of one segment from rows [begin, end) of the table.
struct ChannelMap {
  Column height, deflection, force, time;
  double height_sign = 1.0;
};

Segment make_segment(const TextTable& table, const ChannelMap& map, std::size_t begin, std::size_t end,
                     const std::string& origin, std::vector<std::string>& notes) {
  // Trailing padding: rows at the end where every chosen column is empty (NaN).
  const Column* cols[] = {&map.height, &map.deflection, &map.force, &map.time};
  auto row_empty = [&](std::size_t r) {
    for (const Column* c : cols)
      if (c->index >= 0 && !std::isnan(table.columns[static_cast<std::size_t>(c->index)][r])) return false;
    return true;
  };
  std::size_t last = end;
  while (last > begin && row_empty(last - 1)) --last;
  if (last < end)
    notes.push_back(fmt::format("lines {}-{}: {} row{} of empty (NaN) padding at the end of a segment dropped",
                                table.row_line[last], table.row_line[end - 1], end - last, end - last == 1 ? "" : "s"));
  Segment seg;
  auto fill = [&](const Column& c, double sign) {
    std::vector<double> out;
    if (c.index < 0) return out;
    const auto& src = table.columns[static_cast<std::size_t>(c.index)];
    out.resize(last - begin);
    const double f = sign * c.unit.scale;
    for (std::size_t r = begin; r < last; ++r) {
      const double v = src[r];
      if (std::isnan(v))
        throw InputError(fmt::format("{}: line {}, column {}: missing value (empty or NaN) in the middle of the data "
                                     "(only padding at the end of a segment is allowed)",
                                     origin, table.row_line[r], c.index + 1));
      out[r - begin] = v * f;
    }
    return out;
  };
  seg.height = fill(map.height, map.height_sign);
  auto route = [&](const Column& c) {
    if (c.index < 0) return;
    std::vector<double>* target = nullptr;
    switch (c.unit.quantity) {
      case Quantity::length: target = &seg.deflection; break;
      case Quantity::voltage:
      case Quantity::current: target = &seg.deflection_volts; break;
      case Quantity::force: target = &seg.force; break;
      case Quantity::time: break;
    }
    if (target == nullptr) return;
    if (!target->empty())
      throw InputError(fmt::format("{}: the deflection and force columns both give the {} (column {}): choose one",
                                   origin, c.unit.quantity == Quantity::force ? "force" : "deflection", c.index + 1));
    *target = fill(c, 1.0);
  };
  route(map.deflection);
  route(map.force);
  seg.time = fill(map.time, 1.0);
  return seg;
}

void require_retract(const RawCurve& curve, const std::string& origin, const std::string& format) {
  for (const Segment& s : curve.segments)
    if (s.kind == SegmentKind::retract && s.size() > 0) return;
  throw InputError(fmt::format("{}: no retract part (the {} preset reads curves with an approach and a retract)",
                               origin, format));
}

double height_sign_of(const std::string& direction, const Preset& preset, const std::string& origin) {
  if (direction == "auto") return preset.height_sign;
  if (direction == "away") return 1.0;
  if (direction == "towards") return -1.0;
  throw InputError(fmt::format("{}: height direction '{}' is not one of auto, away, towards", origin, direction));
}

TextSyntax syntax_of(const ReadOptions& options, const Preset& preset, const std::string& origin) {
  TextSyntax s = preset.syntax;
  const std::string& sep = options.separator;
  if (sep == "tab") s.separator = '\t';
  else if (sep == "semicolon" || sep == ";") s.separator = ';';
  else if (sep == "comma" || sep == ",") s.separator = ',';
  else if (sep == "blank" || sep == "space") s.separator = ' ';
  else if (sep != "auto")
    throw InputError(fmt::format("{}: separator '{}' is not one of auto, tab, semicolon, comma, blank", origin, sep));
  if (options.decimal == "point") s.decimal = 0;
  else if (options.decimal == "comma") s.decimal = 1;
  else if (options.decimal != "auto")
    throw InputError(fmt::format("{}: decimal mark '{}' is not one of auto, point, comma", origin, options.decimal));
  if (s.separator == ',' && s.decimal == 1)
    throw InputError(fmt::format("{}: a comma cannot be both the separator and the decimal mark", origin));
  return s;
}

}  // namespace

bool is_text_format(const std::string& format) { return find_preset(format) != nullptr; }

std::vector<RawCurve> read_text_curves(std::string_view bytes, const std::string& origin, const ReadOptions& options) {
  const std::string format = options.format == "auto" ? "text" : options.format;
  const Preset* preset_ptr = find_preset(format);
  if (preset_ptr == nullptr)
    throw InputError(fmt::format("{}: '{}' is not a text format ({})", origin, format, text_format_names()));
  const Preset& preset = *preset_ptr;
  const TextSyntax syntax = syntax_of(options, preset, origin);
  TextTable table;
  try {
    table = parse_text_table(bytes, origin, syntax);
  } catch (const InputError& e) {
    if (preset.signature.empty()) throw;
    throw InputError(fmt::format("{} (the {} preset expects {})", e.what(), format, preset.signature));
  }
  check_signature(preset, table, origin);

  // The header: the header row, or (JPK) the "# columns:" / "# units:" comments.
  std::vector<HeaderCell> header;
  int header_line = table.header_line;
  for (const auto& cell : table.header) header.push_back(parse_header_cell(cell));
  for (std::size_t i = 0; i < table.header_units.size() && i < header.size(); ++i)
    if (header[i].unit.empty()) header[i].unit = table.header_units[i];
  if (preset.comment_header) {
    if (const auto ch = comment_header(table, origin)) {
      header.clear();
      for (std::size_t i = 0; i < ch->names.size(); ++i) {
        HeaderCell cell;
        cell.name = cell.raw = ch->names[i];
        if (i < ch->units.size()) cell.unit = ch->units[i];
        header.push_back(std::move(cell));
      }
      header_line = ch->line;
    }
  }

  RawCurve curve;
  curve.origin = origin;
  curve.metadata.format = format;
  curve.metadata.instrument = preset.instrument;
  read_metadata(preset, table.preamble, curve.metadata, curve.notes, origin);
  if (!std::isnan(options.spring_constant)) curve.metadata.spring_constant = options.spring_constant;
  if (!std::isnan(options.invols)) curve.metadata.invols = options.invols;

  const std::size_t ncol = table.columns.size();
  auto pick = [&](const Role& role, const ColumnChoice& user) {
    return resolve(role, user, header, header_line, ncol, origin, format);
  };
  ChannelMap approach;
  approach.height_sign = height_sign_of(options.height_direction, preset, origin);
  approach.height = pick(preset.height, options.height);
  approach.deflection = pick(preset.deflection, options.deflection);
  approach.force = pick(preset.force, options.force);
  approach.time = pick(preset.time, options.time);
  if (approach.deflection.index < 0 && approach.force.index < 0)
    throw InputError(fmt::format("{}: no deflection or force column{}: choose one by name or position", origin,
                                 header.empty() ? std::string(" (no header row)")
                                                : fmt::format(" in the header (line {}: {})", header_line,
                                                              describe_header(header))));
  const bool user_side = options.retract_height.given() || options.retract_deflection.given() ||
                         options.retract_force.given();
  if (preset.side_by_side || user_side) {
    ChannelMap retract = approach;
    Role rh = preset.retract_height, rd = preset.retract_deflection, rf = preset.retract_force;
    if (user_side && !preset.side_by_side) rh.required = rd.required = rf.required = false;
    retract.height = pick(rh, options.retract_height);
    retract.deflection = pick(rd, options.retract_deflection);
    retract.force = pick(rf, options.retract_force);
    retract.time = pick(preset.retract_time, ColumnChoice{});
    if (retract.height.index < 0) retract.height = approach.height;  // one height axis for both (NT-MDT)
    if (retract.deflection.index < 0 && retract.force.index < 0)
      throw InputError(fmt::format("{}: no retract deflection or force column{}", origin,
                                   preset.side_by_side ? fmt::format(" (the {} preset expects {})", format,
                                                                     preset.retract_deflection.expected)
                                                       : std::string()));
    if (preset.format == "ntmdt-txt") {
      // NT-MDT exports may begin with rows of one repeated deflection value (export padding or a saturated
      // detector at the contact end): kept as read, but said, since it looks like a flat contact region.
      for (const Column* c : {&approach.deflection, &retract.deflection}) {
        if (c->index < 0) continue;
        const auto& v = table.columns[static_cast<std::size_t>(c->index)];
        std::size_t k = 1;
        while (k < v.size() && v[k] == v[0]) ++k;
        if (k >= 10)
          curve.notes.push_back(fmt::format("lines {}-{}: column {} repeats one value ({:g}) {} times (export "
                                            "padding or a saturated detector): kept as read",
                                            table.row_line[0], table.row_line[k - 1], c->index + 1, v[0], k));
      }
    }
    Segment a = make_segment(table, approach, 0, table.rows(), origin, curve.notes);
    Segment r = make_segment(table, retract, 0, table.rows(), origin, curve.notes);
    // Side by side, the rows need not be in recording order (NT-MDT sorts both by height): an approach runs
    // towards the sample (height decreasing), a retract away from it; a column the other way round is reversed.
    auto orient = [&](Segment& s, SegmentKind kind) {
      s.kind = kind;
      if (s.height.size() < 2) return;
      const bool decreasing = s.height.back() < s.height.front();
      if (decreasing == (kind == SegmentKind::approach)) return;
      for (auto* ch : {&s.height, &s.deflection, &s.deflection_volts, &s.force, &s.time})
        std::reverse(ch->begin(), ch->end());
      curve.notes.push_back(fmt::format("the {} columns run in the direction opposite to the {} (rows sorted by "
                                        "height): reversed into recording order",
                                        to_string(kind), to_string(kind)));
    };
    orient(a, SegmentKind::approach);
    orient(r, SegmentKind::retract);
    if (a.size() > 0) curve.segments.push_back(std::move(a));
    if (r.size() > 0) curve.segments.push_back(std::move(r));
  } else {
    // Segment boundaries: a segment column, segment labels in comments (JPK), or the turning point of the height.
    std::vector<std::pair<std::size_t, SegmentKind>> starts;  // (first row, kind)
    const Column seg = pick(preset.segment, options.segment);
    if (seg.index >= 0) {
      const auto& s = table.columns[static_cast<std::size_t>(seg.index)];
      const auto& h = table.columns[static_cast<std::size_t>(approach.height.index)];
      double previous = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t r = 0; r < s.size(); ++r) {
        if (std::isnan(s[r])) {
          if (std::isnan(h[r])) continue;  // padding: make_segment drops it (or refuses a hole)
          throw InputError(fmt::format("{}: line {}, column {}: the segment column has no value", origin,
                                       table.row_line[r], seg.index + 1));
        }
        if (starts.empty() || s[r] != previous) starts.emplace_back(starts.empty() ? 0 : r, SegmentKind::unknown);
        previous = s[r];
      }
    } else if (preset.comment_segments) {
      for (const TextLine& l : table.preamble)
        if (auto label = segment_label(l.text)) starts.assign(1, {0, kind_from_label(*label)});
      for (const TextLine& l : table.interludes)
        if (auto label = segment_label(l.text)) {
          if (!starts.empty() && starts.back().first == l.row) starts.back().second = kind_from_label(*label);
          else starts.emplace_back(l.row, kind_from_label(*label));
        }
      if (!starts.empty() && starts.front().first != 0) starts.insert(starts.begin(), {0, SegmentKind::unknown});
    }
    if (starts.empty()) {
      // The turning point: the lowest (or highest) height, when it is inside the curve.
      const auto& h = table.columns[static_cast<std::size_t>(approach.height.index)];
      std::size_t n = h.size();
      while (n > 0 && std::isnan(h[n - 1])) --n;
      starts.emplace_back(0, SegmentKind::unknown);
      if (n >= 3) {
        std::size_t imin = 0, imax = 0;
        for (std::size_t r = 1; r < n; ++r) {
          const double v = approach.height_sign * h[r];
          if (v < approach.height_sign * h[imin]) imin = r;
          if (v > approach.height_sign * h[imax]) imax = r;
        }
        // Down to the lowest point then up: approach then retract (or the reverse around the highest point).
        if (imin > 0 && imin + 1 < n) {
          starts.front().second = SegmentKind::approach;
          starts.emplace_back(imin + 1, SegmentKind::retract);
        } else if (imax > 0 && imax + 1 < n) {
          starts.front().second = SegmentKind::retract;
          starts.emplace_back(imax + 1, SegmentKind::approach);
        }
      }
    }
    for (std::size_t i = 0; i < starts.size(); ++i) {
      const std::size_t begin = starts[i].first;
      const std::size_t end = i + 1 < starts.size() ? starts[i + 1].first : table.rows();
      if (end <= begin) continue;
      Segment s = make_segment(table, approach, begin, end, origin, curve.notes);
      if (s.size() == 0) continue;
      s.kind = starts[i].second != SegmentKind::unknown ? starts[i].second : kind_from_height(s.height);
      curve.segments.push_back(std::move(s));
    }
  }
  if (curve.segments.empty()) throw InputError(fmt::format("{}: no data (every row is empty)", origin));
  if (preset.require_retract) require_retract(curve, origin, format);
  std::vector<RawCurve> out;
  out.push_back(std::move(curve));
  return out;
}

}  // namespace afmkit::io::curves::detail
