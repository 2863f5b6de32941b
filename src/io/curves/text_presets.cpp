#include "text_presets.hpp"
#include "text_table.hpp"

#include <array>
#include <cctype>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"

namespace afmkit::io::curves::detail {

namespace {

const std::vector<Quantity> kLength{Quantity::length};
const std::vector<Quantity> kDeflection{Quantity::length, Quantity::voltage, Quantity::current, Quantity::force};
const std::vector<Quantity> kForce{Quantity::force};
const std::vector<Quantity> kTime{Quantity::time};

Role role(const char* name, std::vector<Candidate> candidates, const std::vector<Quantity>& quantities,
          bool required = false, std::string expected = {}, int position = 0, std::string unit = {}) {
  Role r;
  r.name = name;
  r.candidates = std::move(candidates);
  r.quantities = quantities;
  r.required = required;
  r.expected = std::move(expected);
  r.default_position = position;
  r.default_unit = std::move(unit);
  return r;
}

MetadataKey key(MetadataKey::Target target, std::string name) {
  MetadataKey k{target, std::move(name), 1.0, false, std::nullopt};
  return k;
}

// The roles every preset has unless it says otherwise (not required, no candidates).
Preset base(std::string format, std::string instrument) {
  Preset p;
  p.format = std::move(format);
  p.instrument = std::move(instrument);
  p.height = role("height", {}, kLength, true);
  p.deflection = role("deflection", {}, kDeflection);
  p.force = role("force", {}, kForce);
  p.time = role("time", {}, kTime);
  p.segment = role("segment", {}, {});
  p.retract_height = role("retract height", {}, kLength);
  p.retract_deflection = role("retract deflection", {}, kDeflection);
  p.retract_force = role("retract force", {}, kForce);
  p.retract_time = role("retract time", {}, kTime);
  return p;
}

Preset make_text() {
  Preset p = base("text", "text");
  p.height = role("height",
                  {{"~height", ""}, {"~zsnsr", ""}, {"~z-sense", ""}, {"~zsensor", ""}, {"~z sensor", ""},
                   {"~ramp", ""}, {"~piezo", ""}, {"~lvdt", ""}, {"z", ""}, {"h", ""}, {"~extension", ""}},
                  kLength, true, "", 1);
  p.deflection = role("deflection", {{"~defl", ""}, {"~t-b", ""}}, kDeflection, false, "", 2);
  p.force = role("force", {{"~force", ""}}, kForce);
  p.time = role("time", {{"~time", ""}, {"t", ""}}, kTime);
  p.segment = role("segment", {{"~segment", ""}}, {});
  p.metadata = {key(MetadataKey::spring_constant, "spring constant"), key(MetadataKey::spring_constant, "springConstant"),
                key(MetadataKey::spring_constant, "SpringConstant"), key(MetadataKey::invols, "InvOLS"),
                key(MetadataKey::invols, "sensitivity")};
  return p;
}

// JPK Data Processing, "export as text": "# name: value" comments (springConstant [N/m], sensitivity [m/V]), and
// for each segment "# segment: extend|retract|pause", "# columns: height vDeflection ...", "# units: m N ...".
Preset make_jpk_txt() {
  Preset p = base("jpk-txt", "JPK");
  p.comment_header = p.comment_segments = true;
  p.require_retract = true;
  p.height = role("height",
                  {{"measuredHeight", ""}, {"strainGaugeHeight", ""}, {"capacitiveSensorHeight", ""},
                   {"smoothedMeasuredHeight", ""}, {"smoothedStrainGaugeHeight", ""},
                   {"smoothedCapacitiveSensorHeight", ""}, {"height", ""}},
                  kLength, true, "'measuredHeight', 'strainGaugeHeight', 'capacitiveSensorHeight' or 'height'");
  p.deflection = role("deflection", {{"vDeflection", ""}}, kDeflection, true, "'vDeflection'");
  p.time = role("time", {{"seriesTime", ""}}, kTime);
  p.metadata = {key(MetadataKey::spring_constant, "springConstant"), key(MetadataKey::invols, "sensitivity")};
  p.signature = "'# columns:' and '# segment:' comments (JPK Data Processing text export)";
  return p;
}

// Asylum Research (Igor Pro) force curve waves saved as delimited text: one column per wave, named as the wave
// ("...Raw", "...Defl", "...ZSnsr", "...Time"), SI values without units; the note's "SpringConstant: k" and
// "InvOLS: s" lines when exported. ZSnsr grows towards the sample: height = -ZSnsr.
Preset make_asylum_txt() {
  Preset p = base("asylum-txt", "Asylum Research");
  p.height_sign = -1.0;
  p.require_retract = true;
  p.height = role("height", {{"*ZSnsr", "m"}, {"*ZSensor", "m"}, {"*LVDT", "m"}}, kLength, true, "a '...ZSnsr' column");
  p.deflection = role("deflection", {{"*Defl", "m"}, {"*Deflection", "m"}, {"*Raw", "V"}}, kDeflection, false,
                      "a '...Defl' or '...Raw' column");
  p.force = role("force", {{"*Force", "N"}}, kForce);
  p.time = role("time", {{"*Time", "s"}}, kTime);
  p.metadata = {key(MetadataKey::spring_constant, "SpringConstant"), key(MetadataKey::invols, "InvOLS")};
  p.signature = "a header row with a '...ZSnsr' column (Asylum Research waves as text)";
  return p;
}

// Bruker NanoScope Analysis "Export > Force Curve ASCII" of ramp data: approach ("_Ex") and retract ("_Rt")
// columns side by side, the unit inside the name ("Calc_Ramp_Ex_nm", "Defl_nm_Ex", "Defl_pN_Ex", "Defl_V_Ex").
// The ramp (piezo extension) grows towards the sample: height = -ramp.
Preset make_nanoscope_txt() {
  Preset p = base("nanoscope-txt", "Bruker Nanoscope");
  p.height_sign = -1.0;
  p.side_by_side = p.require_retract = true;
  p.height = role("height", {{"Calc_Ramp_Ex", ""}, {"Height_Sensor_Ex", ""}, {"ZSensor_Ex", ""}}, kLength, true,
                  "'Calc_Ramp_Ex_nm' (or 'Height_Sensor_Ex_nm', 'ZSensor_Ex_nm')");
  p.retract_height = role("retract height",
                          {{"Calc_Ramp_Rt", ""}, {"Cal_Ramp_Rt", ""}, {"Height_Sensor_Rt", ""}, {"ZSensor_Rt", ""}},
                          kLength, true, "'Calc_Ramp_Rt_nm' (or 'Height_Sensor_Rt_nm', 'ZSensor_Rt_nm')");
  p.deflection = role("deflection", {{"Defl_Ex", ""}, {"Deflection_Ex", ""}}, kDeflection, false,
                      "'Defl_nm_Ex', 'Defl_pN_Ex' or 'Defl_V_Ex'");
  p.retract_deflection = role("retract deflection", {{"Defl_Rt", ""}, {"Deflection_Rt", ""}}, kDeflection, false,
                              "'Defl_nm_Rt', 'Defl_pN_Rt' or 'Defl_V_Rt'");
  p.force = role("force", {{"Force_Ex", ""}}, kForce);
  p.retract_force = role("retract force", {{"Force_Rt", ""}}, kForce);
  p.time = role("time", {{"Time_Ex", ""}}, kTime);
  p.retract_time = role("retract time", {{"Time_Rt", ""}}, kTime);
  p.metadata = {key(MetadataKey::spring_constant, "Spring Constant"), key(MetadataKey::spring_constant, "Spring constant")};
  p.signature = "a header row with '..._Ex' and '..._Rt' ramp columns (NanoScope force curve ASCII export)";
  return p;
}

// NT-MDT Nova text export of a curve: three tab-separated columns without header or metadata, decimal comma per
// the locale: height [nm] (growing away from the sample), the approach's and the retract's deflection signal
// (DFL, nA), both sorted by height.
Preset make_ntmdt_txt() {
  Preset p = base("ntmdt-txt", "NT-MDT");
  p.side_by_side = p.require_retract = true;
  p.height = role("height", {}, kLength, true, "column 1: height [nm]", 1, "nm");
  p.deflection = role("deflection", {}, kDeflection, true, "column 2: approach DFL [nA]", 2, "nA");
  p.retract_deflection = role("retract deflection", {}, kDeflection, true, "column 3: retract DFL [nA]", 3, "nA");
  p.signature = "three columns of numbers (height, approach and retract deflection) without header or metadata";
  return p;
}

// AFM Workshop "Force-Distance Curve" CSV: metadata lines "key:<TAB>value", then
// "Extend Z-Sense(nm),Extend T-B(V) or Extend Force(nN),Retract Z-Sense(nm),Retract ...". Z-Sense grows towards
// the sample: height = -Z-Sense. "Force Constant, nN/nm" and "Light Lever Gain, mV/nm" of 1 are placeholders.
Preset make_afmworkshop_csv() {
  Preset p = base("afmworkshop-csv", "AFM Workshop");
  p.height_sign = -1.0;
  p.side_by_side = p.require_retract = true;
  p.syntax.separator = ',';
  p.height = role("height", {{"Extend Z-Sense", "nm"}}, kLength, true, "'Extend Z-Sense(nm)'");
  p.retract_height = role("retract height", {{"Retract Z-Sense", "nm"}}, kLength, true, "'Retract Z-Sense(nm)'");
  p.deflection = role("deflection", {{"Extend T-B", "V"}}, kDeflection, false, "'Extend T-B(V)'");
  p.force = role("force", {{"Extend Force", "nN"}}, kForce, false, "'Extend Force(nN)'");
  p.retract_deflection = role("retract deflection", {{"Retract T-B", "V"}}, kDeflection, false,
                              "'Retract T-B(V)' or 'Retract Force(nN)'");
  p.retract_force = role("retract force", {{"Retract Force", "nN"}}, kForce);
  MetadataKey k{MetadataKey::spring_constant, "Force Constant, nN/nm", 1.0, false, 1.0};
  MetadataKey s{MetadataKey::invols, "Light Lever Gain, mV/nm", 1e6, true, 1.0};  // mV/nm = 1e6 V/m
  p.metadata = {k, s};
  p.signature = "a first line 'Force-Distance Curve' (AFM Workshop CSV)";
  return p;
}

const std::array<Preset, 6>& presets() {
  static const std::array<Preset, 6> all{make_text(),          make_jpk_txt(),   make_asylum_txt(),
                                         make_nanoscope_txt(), make_ntmdt_txt(), make_afmworkshop_csv()};
  return all;
}

bool header_has(const TextTable& table, std::string_view suffix) {
  const std::string s = lower(suffix);
  for (const auto& cell : table.header) {
    const std::string c = lower(cell);
    if (c.find(s) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

const Preset* find_preset(const std::string& format) {
  for (const Preset& p : presets())
    if (p.format == format) return &p;
  return nullptr;
}

const char* text_format_names() { return "text, jpk-txt, asylum-txt, nanoscope-txt, ntmdt-txt, afmworkshop-csv"; }

std::optional<std::string> segment_label(std::string_view comment) {
  const std::string l = lower(comment);
  if (l.rfind("segment:", 0) != 0) return std::nullopt;
  return std::string(trim(comment.substr(8)));
}

std::optional<CommentHeader> comment_header(const TextTable& table, const std::string& origin) {
  std::optional<CommentHeader> out;
  auto words = [](std::string_view s) {
    std::vector<std::string> w;
    for (std::string_view c : split_cells(s, ' ')) w.emplace_back(c);
    return w;
  };
  auto scan = [&](const TextLine& l) {
    const std::string low = lower(l.text);
    if (low.rfind("columns:", 0) == 0) {
      CommentHeader h;
      h.names = words(std::string_view(l.text).substr(8));
      h.line = l.line;
      if (h.names.size() != table.columns.size())
        throw InputError(fmt::format("{}: line {}: '# columns:' names {} columns, the data have {}", origin, l.line,
                                     h.names.size(), table.columns.size()));
      if (out && out->names != h.names)
        throw InputError(fmt::format("{}: line {}: the segment's columns differ from those of line {}", origin,
                                     l.line, out->line));
      if (!out) out = std::move(h);
    } else if (low.rfind("units:", 0) == 0 && out) {
      auto units = words(std::string_view(l.text).substr(6));
      if (units.size() != out->names.size())
        throw InputError(fmt::format("{}: line {}: '# units:' gives {} units for {} columns", origin, l.line,
                                     units.size(), out->names.size()));
      if (!out->units.empty() && units != out->units)
        throw InputError(fmt::format("{}: line {}: the segment's units differ from those of the first segment",
                                     origin, l.line));
      out->units = std::move(units);
    }
  };
  for (const TextLine& l : table.preamble) scan(l);
  for (const TextLine& l : table.interludes) scan(l);
  return out;
}

void check_signature(const Preset& preset, const TextTable& table, const std::string& origin) {
  bool ok = true;
  int line = table.row_line.empty() ? 1 : table.row_line.front();
  if (preset.format == "jpk-txt") {
    bool columns = false, segment = false;
    for (const auto* lines : {&table.preamble, &table.interludes})
      for (const TextLine& l : *lines) {
        columns = columns || lower(l.text).rfind("columns:", 0) == 0;
        segment = segment || segment_label(l.text).has_value();
      }
    ok = columns && segment;
  } else if (preset.format == "asylum-txt") {
    ok = header_has(table, "zsnsr") || header_has(table, "zsensor") || header_has(table, "lvdt");
    line = table.header_line > 0 ? table.header_line : line;
  } else if (preset.format == "nanoscope-txt") {
    ok = header_has(table, "_ex") && header_has(table, "_rt");
    line = table.header_line > 0 ? table.header_line : line;
  } else if (preset.format == "ntmdt-txt") {
    ok = table.header.empty() && table.columns.size() == 3;
    for (const TextLine& l : table.preamble) {
      ok = false;
      line = l.line;
      break;
    }
    if (!table.header.empty()) line = table.header_line;
  } else if (preset.format == "afmworkshop-csv") {
    ok = !table.preamble.empty() && table.preamble.front().text == "Force-Distance Curve";
    line = table.preamble.empty() ? line : table.preamble.front().line;
  }
  if (!ok)
    throw InputError(fmt::format("{}: line {}: not the layout of the {} preset ({}), which expects {}", origin, line,
                                 preset.format, preset.instrument, preset.signature));
}

}  // namespace afmkit::io::curves::detail
