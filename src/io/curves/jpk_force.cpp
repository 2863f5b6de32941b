// JPK .jpk-force (docs/curve-files.md#jpk-force): a zip archive of Java properties headers and big-endian binary
// channels. header.properties (the series), optionally shared-data/header.properties (channel definitions shared
// by the segments: "lcd-info.<n>.*", referenced from a segment as "channel.<name>.lcd-info.*=<n>"),
// segments/<n>/segment-header.properties (style extend/retract/pause, num-points, duration, the channels) and
// segments/<n>/channels/<name>.dat. A force map holds one such curve per index/<i>/.
// Raw integers -> volts by the encoder's offset and multiplier; volts -> distance -> force (vDeflection) or
// nominal / calibrated / absolute height by the conversion set's chain of linear conversions.
#include <zip.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"
#include "binary_readers.hpp"
#include "properties.hpp"

namespace afmkit::io::curves::detail {

namespace {

// A zip archive in memory, read through libzip with every entry's declared size checked before it is allocated.
class ZipArchive {
 public:
  ZipArchive(std::string_view bytes, const std::string& origin) : origin_(origin) {
    zip_error_t error;
    zip_error_init(&error);
    static const char empty = 0;
    zip_source_t* source = zip_source_buffer_create(bytes.empty() ? &empty : bytes.data(), bytes.size(), 0, &error);
    if (source == nullptr) fail_open(&error);
    archive_ = zip_open_from_source(source, ZIP_RDONLY | ZIP_CHECKCONS, &error);
    if (archive_ == nullptr) {
      zip_source_free(source);
      fail_open(&error);
    }
    compressed_total_ = bytes.size();
  }
  ~ZipArchive() {
    if (archive_ != nullptr) zip_discard(archive_);
  }
  ZipArchive(const ZipArchive&) = delete;
  ZipArchive& operator=(const ZipArchive&) = delete;

  std::vector<std::string> names() const {
    std::vector<std::string> out;
    const zip_int64_t n = zip_get_num_entries(archive_, 0);
    for (zip_int64_t i = 0; i < n; ++i)
      if (const char* name = zip_get_name(archive_, static_cast<zip_uint64_t>(i), 0)) out.emplace_back(name);
    return out;
  }

  bool has(const std::string& name) const { return zip_name_locate(archive_, name.c_str(), 0) >= 0; }

  /// The content of entry `name`; InputError naming the entry when it is missing, larger than its compressed size
  /// allows, larger than this run may hold, or cannot be read whole (truncated, bad checksum).
  std::string read(const std::string& name) const {
    const zip_int64_t index = zip_name_locate(archive_, name.c_str(), 0);
    if (index < 0) throw InputError(fmt::format("{}: the archive has no entry '{}'", origin_, name));
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(archive_, static_cast<zip_uint64_t>(index), 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE) ||
        !(st.valid & ZIP_STAT_COMP_SIZE))
      throw InputError(fmt::format("{}: entry '{}': no size in the archive's directory", origin_, name));
    // Deflate compresses at most ~1032:1; a declared size beyond that (or beyond the file) is a lie, refused
    // before anything is allocated.
    const std::uint64_t bound = std::min<std::uint64_t>(1100 * std::max<std::uint64_t>(st.comp_size, 1) + 4096,
                                                        files::input_size_limit());
    if (st.size > bound || st.comp_size > compressed_total_)
      throw InputError(fmt::format("{}: entry '{}' declares {} bytes ({} compressed, archive {} bytes): more than "
                                   "it can hold",
                                   origin_, name, st.size, st.comp_size, compressed_total_));
    std::unique_ptr<zip_file_t, int (*)(zip_file_t*)> file(zip_fopen_index(archive_, static_cast<zip_uint64_t>(index), 0),
                                                           zip_fclose);
    if (!file)
      throw InputError(fmt::format("{}: entry '{}' cannot be opened: {}", origin_, name, zip_strerror(archive_)));
    std::string out(static_cast<std::size_t>(st.size), '\0');
    std::size_t got = 0;
    while (got < out.size()) {
      const zip_int64_t n = zip_fread(file.get(), out.data() + got, out.size() - got);
      if (n < 0)
        throw InputError(fmt::format("{}: entry '{}' cannot be read: {}", origin_, name, zip_file_strerror(file.get())));
      if (n == 0) break;
      got += static_cast<std::size_t>(n);
    }
    char extra;
    if (got != out.size() || zip_fread(file.get(), &extra, 1) != 0)
      throw InputError(fmt::format("{}: entry '{}' is truncated or corrupt ({} of {} bytes read)", origin_, name, got,
                                   out.size()));
    return out;
  }

 private:
  [[noreturn]] void fail_open(zip_error_t* error) {
    const std::string what = zip_error_strerror(error);
    zip_error_fini(error);
    throw InputError(fmt::format("{}: not a readable JPK .jpk-force file (a zip archive): {}", origin_, what));
  }

  std::string origin_;
  zip_t* archive_ = nullptr;
  std::uint64_t compressed_total_ = 0;
};

struct Context {
  std::string origin;
  std::string entry;  // the segment header, for messages
  Properties props;   // general + index + segment header, shared lcd-info substituted
};

const std::string* find(const Properties& p, const std::string& key) {
  const auto it = p.find(key);
  return it == p.end() ? nullptr : &it->second;
}

double number(const Context& c, const std::string& key) {
  const std::string* v = find(c.props, key);
  if (v == nullptr) throw InputError(fmt::format("{}: {}: no '{}'", c.origin, c.entry, key));
  char* end = nullptr;
  const double x = std::strtod(v->c_str(), &end);
  if (v->empty() || end != v->c_str() + v->size() || !std::isfinite(x))
    throw InputError(fmt::format("{}: {}: '{}' = '{}' is not a finite number", c.origin, c.entry, key, *v));
  return x;
}

// A channel's property: "channel.<ch>.data.<suffix>" (old layout), else "channel.<ch>.<suffix>" (shared lcd-info).
const std::string* channel_prop(const Context& c, const std::string& ch, const std::string& suffix) {
  if (const auto* v = find(c.props, "channel." + ch + ".data." + suffix)) return v;
  return find(c.props, "channel." + ch + "." + suffix);
}

double channel_number(const Context& c, const std::string& ch, const std::string& suffix) {
  if (find(c.props, "channel." + ch + ".data." + suffix)) return number(c, "channel." + ch + ".data." + suffix);
  return number(c, "channel." + ch + "." + suffix);
}

// The channel's samples in its base unit (volts): big-endian integers through the encoder, or floats.
std::vector<double> decode(const Context& c, const std::string& ch, const std::string& bytes, std::size_t points,
                           const std::string& entry) {
  const std::string* type = channel_prop(c, ch, "type");
  const std::string* encoder = channel_prop(c, ch, "encoder.type");
  std::string kind = type ? *type : "";
  int width = 0;
  bool is_float = false, is_signed = true;
  if (kind.find("float") != std::string::npos) {
    width = 4;
    is_float = true;
  } else if (kind.find("double") != std::string::npos) {
    width = 8;
    is_float = true;
  } else {
    if (encoder == nullptr)
      throw InputError(fmt::format("{}: {}: channel '{}' has no encoder type", c.origin, c.entry, ch));
    const std::string& e = *encoder;
    if (e == "signedshort" || e == "unsignedshort") width = 2;
    else if (e == "signedinteger" || e == "unsignedinteger") width = 4;
    else if (e == "signedlong" || e == "unsignedlong") width = 8;
    else
      throw InputError(fmt::format("{}: {}: channel '{}': encoder type '{}' is not signed/unsigned short, integer or "
                                   "long",
                                   c.origin, c.entry, ch, e));
    is_signed = e.rfind("signed", 0) == 0;
  }
  if (bytes.size() != points * static_cast<std::size_t>(width))
    throw InputError(fmt::format("{}: entry '{}': {} bytes, but {} points of {} bytes declared", c.origin, entry,
                                 bytes.size(), points, width));
  double mult = 1.0, off = 0.0;
  if (channel_prop(c, ch, "encoder.scaling.multiplier")) {
    mult = channel_number(c, ch, "encoder.scaling.multiplier");
    off = channel_number(c, ch, "encoder.scaling.offset");
  } else if (!is_float) {
    throw InputError(fmt::format("{}: {}: channel '{}' has no encoder scaling", c.origin, c.entry, ch));
  }
  std::vector<double> out(points);
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  for (std::size_t i = 0; i < points; ++i, p += width) {
    std::uint64_t u = 0;
    for (int b = 0; b < width; ++b) u = (u << 8) | p[b];
    double raw;
    if (is_float && width == 4) {
      const auto v32 = static_cast<std::uint32_t>(u);
      float f;
      std::memcpy(&f, &v32, 4);
      raw = f;
    } else if (is_float) {
      std::memcpy(&raw, &u, 8);
    } else if (is_signed) {
      const int shift = 64 - 8 * width;
      raw = static_cast<double>(static_cast<std::int64_t>(u << shift) >> shift);
    } else {
      raw = static_cast<double>(u);
    }
    if (!std::isfinite(raw))
      throw InputError(fmt::format("{}: entry '{}': sample {} is not a finite number", c.origin, entry, i + 1));
    out[i] = raw * mult + off;
  }
  return out;
}

// The linear chain from the base (volts) to `slot`: multiplier and offset of each step, the slot's unit.
struct Conversion {
  std::vector<std::pair<double, double>> steps;  // applied in order
  std::string unit;
};

std::optional<Conversion> conversion(const Context& c, const std::string& ch, const std::string& slot) {
  const std::string set = "channel." + ch + ".conversion-set.";
  const std::string* base = find(c.props, set + "conversions.base");
  if (base == nullptr) return std::nullopt;
  Conversion conv;
  std::string cur = slot;
  for (int guard = 0; cur != *base; ++guard) {
    if (guard > 16)
      throw InputError(fmt::format("{}: {}: channel '{}': the conversions from '{}' do not reach the base '{}'",
                                   c.origin, c.entry, ch, slot, *base));
    const std::string key = set + "conversion." + cur + ".";
    const std::string* defined = find(c.props, key + "defined");
    if (defined == nullptr || *defined != "true") return std::nullopt;
    if (const auto* style = find(c.props, key + "scaling.style"); style && *style != "offsetmultiplier")
      throw InputError(fmt::format("{}: {}: channel '{}', conversion '{}': scaling style '{}' is not offsetmultiplier",
                                   c.origin, c.entry, ch, cur, *style));
    conv.steps.emplace_back(number(c, key + "scaling.multiplier"), number(c, key + "scaling.offset"));
    if (conv.unit.empty()) {
      const std::string* unit = find(c.props, key + "scaling.unit.unit");
      if (unit == nullptr) unit = find(c.props, key + "scaling.unit");
      conv.unit = unit ? *unit : "";
    }
    const std::string* next = find(c.props, key + "base-calibration-slot");
    if (next == nullptr) return std::nullopt;
    cur = *next;
  }
  std::reverse(conv.steps.begin(), conv.steps.end());
  return conv;
}

std::vector<double> apply_conversion(const Conversion& conv, std::vector<double> v) {
  for (const auto& [m, o] : conv.steps)
    for (double& x : v) x = x * m + o;
  return v;
}

SegmentKind kind_of(const Context& c) {
  for (const char* key : {"force-segment-header.settings.style", "force-segment-header.settings.segment-settings.style"})
    if (const auto* s = find(c.props, key)) {
      if (*s == "extend") return SegmentKind::approach;
      if (*s == "retract") return SegmentKind::retract;
      if (*s == "pause") return SegmentKind::pause;
    }
  return SegmentKind::unknown;
}

// Substitutes shared-data channel definitions: "<head>.<mediator>.*=<n>" takes every "<mediator>.<n>.<var>" of the
// shared header as "<head>.<var>".
void substitute_shared(Properties& props, const Properties& shared) {
  std::vector<std::pair<std::string, std::string>> add;
  for (const auto& [key, value] : props) {
    if (key.size() < 2 || key.compare(key.size() - 2, 2, ".*") != 0) continue;
    const std::string stem = key.substr(0, key.size() - 2);  // channel.vDeflection.lcd-info
    const auto dot = stem.rfind('.');
    if (dot == std::string::npos) continue;
    const std::string head = stem.substr(0, dot);
    const std::string prefix = stem.substr(dot + 1) + "." + value + ".";
    for (auto it = shared.lower_bound(prefix); it != shared.end() && it->first.rfind(prefix, 0) == 0; ++it)
      add.emplace_back(head + "." + it->first.substr(prefix.size()), it->second);
  }
  for (auto& [k, v] : add) props.emplace(std::move(k), std::move(v));  // the segment's own keys win
}

std::size_t parse_index(std::string_view s) {
  if (s.empty() || s.size() > 9) return SIZE_MAX;
  std::size_t n = 0;
  for (char ch : s) {
    if (ch < '0' || ch > '9') return SIZE_MAX;
    n = n * 10 + static_cast<std::size_t>(ch - '0');
  }
  return n;
}

RawCurve read_one(const ZipArchive& zip, const std::vector<std::string>& names, const std::string& prefix,
                  const Properties& general, const Properties& shared, const std::string& origin,
                  const ReadOptions& options) {
  RawCurve curve;
  curve.origin = prefix.empty() ? origin : fmt::format("{} ({})", origin, prefix.substr(0, prefix.size() - 1));
  curve.metadata.format = "jpk-force";
  curve.metadata.instrument = "JPK";
  if (const auto* inst = find(general, "force-scan-series.description.instrument"); inst && !inst->empty())
    curve.metadata.instrument = "JPK " + *inst;
  Properties base = general;
  if (!prefix.empty() && zip.has(prefix + "header.properties"))
    for (auto& [k, v] : parse_properties(zip.read(prefix + "header.properties"))) base[k] = v;
  std::set<std::size_t> segments;
  const std::string seg_prefix = prefix + "segments/";
  for (const auto& n : names) {
    if (n.rfind(seg_prefix, 0) != 0) continue;
    const auto slash = n.find('/', seg_prefix.size());
    if (slash == std::string::npos || n.compare(slash, std::string::npos, "/segment-header.properties") != 0) continue;
    const std::size_t i = parse_index(std::string_view(n).substr(seg_prefix.size(), slash - seg_prefix.size()));
    if (i != SIZE_MAX) segments.insert(i);
  }
  if (segments.empty())
    throw InputError(fmt::format("{}: the archive has no '{}<n>/segment-header.properties': not a JPK force curve",
                                 origin, seg_prefix));
  double t0 = 0.0;
  for (std::size_t s : segments) {
    Context c;
    c.origin = origin;
    c.entry = fmt::format("entry '{}{}/segment-header.properties'", seg_prefix, s);
    c.props = base;
    for (auto& [k, v] : parse_properties(zip.read(fmt::format("{}{}/segment-header.properties", seg_prefix, s))))
      c.props[k] = v;
    substitute_shared(c.props, shared);
    const double points_d = number(c, "force-segment-header.num-points");
    if (points_d < 0 || points_d != std::floor(points_d) || points_d > 1e12)
      throw InputError(fmt::format("{}: {}: num-points = {} is not a count", origin, c.entry, points_d));
    const auto points = static_cast<std::size_t>(points_d);
    Segment seg;
    seg.kind = kind_of(c);
    const double duration = find(c.props, "force-segment-header.duration")
                                ? number(c, "force-segment-header.duration")
                                : std::numeric_limits<double>::quiet_NaN();
    if (points == 0) {
      if (std::isfinite(duration)) t0 += duration;
      continue;
    }
    auto channel_entry = [&](const std::string& ch) -> std::optional<std::string> {
      const std::string* file = find(c.props, "channel." + ch + ".data.file.name");
      const std::string path = fmt::format("{}{}/{}", seg_prefix, s, file ? *file : "channels/" + ch + ".dat");
      if (!zip.has(path)) return std::nullopt;
      return path;
    };
    // Deflection: volts, distance (m) and force (N).
    if (const auto entry = channel_entry("vDeflection")) {
      const std::vector<double> volts = decode(c, "vDeflection", zip.read(*entry), points, *entry);
      seg.deflection_volts = volts;
      if (const auto d = conversion(c, "vDeflection", "distance"); d && d->unit == "m") {
        seg.deflection = apply_conversion(*d, volts);
        if (d->steps.size() == 1 && d->steps[0].second == 0.0) {
          if (!(d->steps[0].first > 0))
            throw InputError(fmt::format("{}: {}: vDeflection distance multiplier (InvOLS) {} m/V: must be positive",
                                         origin, c.entry, d->steps[0].first));
          curve.metadata.invols = d->steps[0].first;
        }
      }
      if (const auto f = conversion(c, "vDeflection", "force"); f && f->unit == "N") {
        seg.force = apply_conversion(*f, volts);
        if (f->steps.size() == 2 && f->steps[1].second == 0.0) {
          if (!(f->steps[1].first > 0))
            throw InputError(fmt::format("{}: {}: vDeflection force multiplier (spring constant) {} N/m: must be "
                                         "positive",
                                         origin, c.entry, f->steps[1].first));
          curve.metadata.spring_constant = f->steps[1].first;
        }
      }
    } else {
      throw InputError(fmt::format("{}: {}: no vDeflection channel (entry '{}{}/channels/vDeflection.dat')", origin,
                                   c.entry, seg_prefix, s));
    }
    // Height: the measured height (strain gauge / capacitive sensor) when recorded, else the piezo's.
    std::vector<std::string> wanted = {"strainGaugeHeight", "measuredHeight", "capacitiveSensorHeight", "height",
                                       "head-height"};
    if (!options.height.name.empty()) wanted = {options.height.name};
    std::optional<std::string> height_channel, height_entry;
    for (const auto& ch : wanted)
      if (auto e = channel_entry(ch)) {
        height_channel = ch;
        height_entry = e;
        break;
      }
    if (!height_channel)
      throw InputError(fmt::format("{}: {}: no height channel ({})", origin, c.entry,
                                   options.height.name.empty() ? "strainGaugeHeight, measuredHeight, "
                                                                 "capacitiveSensorHeight or height"
                                                               : options.height.name));
    const std::vector<double> hv = decode(c, *height_channel, zip.read(*height_entry), points, *height_entry);
    std::optional<Conversion> hc;
    std::vector<std::string> slots;
    if (const auto* d = find(c.props, "channel." + *height_channel + ".conversion-set.conversions.default"))
      slots.push_back(*d);
    for (const char* s2 : {"calibrated", "nominal", "absolute"}) slots.emplace_back(s2);
    for (const auto& slot : slots)
      if (auto conv = conversion(c, *height_channel, slot); conv && conv->unit == "m") {
        hc = conv;
        break;
      }
    if (!hc)
      throw InputError(fmt::format("{}: {}: channel '{}' has no conversion to metres", origin, c.entry,
                                   *height_channel));
    seg.height = apply_conversion(*hc, hv);
    if (options.height_direction == "towards")
      for (double& h : seg.height) h = -h;
    if (std::isfinite(duration) && duration > 0) {
      seg.time.resize(points);
      for (std::size_t i = 0; i < points; ++i) seg.time[i] = t0 + duration * static_cast<double>(i) / static_cast<double>(points);
      t0 += duration;
    }
    curve.segments.push_back(std::move(seg));
  }
  if (curve.segments.empty()) throw InputError(fmt::format("{}: no segment with data points", curve.origin));
  return curve;
}

}  // namespace

std::vector<RawCurve> read_jpk_force(std::string_view bytes, const std::string& origin, const ReadOptions& options) {
  if (options.height_direction != "auto" && options.height_direction != "away" && options.height_direction != "towards")
    throw InputError(fmt::format("{}: height direction '{}' is not one of auto, away, towards", origin,
                                 options.height_direction));
  const ZipArchive zip(bytes, origin);
  const std::vector<std::string> names = zip.names();
  const Properties general = parse_properties(zip.read("header.properties"));
  const auto* kind = find(general, "jpk-data-file");
  if (kind == nullptr)
    throw InputError(fmt::format("{}: entry 'header.properties' has no 'jpk-data-file': not a JPK file", origin));
  Properties shared;
  if (zip.has("shared-data/header.properties")) shared = parse_properties(zip.read("shared-data/header.properties"));
  std::vector<RawCurve> curves;
  std::set<std::size_t> indices;
  for (const auto& n : names) {
    if (n.rfind("index/", 0) != 0) continue;
    const auto slash = n.find('/', 6);
    if (slash == std::string::npos) continue;
    const std::size_t i = parse_index(std::string_view(n).substr(6, slash - 6));
    if (i != SIZE_MAX) indices.insert(i);
  }
  if (indices.empty()) {
    curves.push_back(read_one(zip, names, "", general, shared, origin, options));
  } else {
    for (std::size_t i : indices)
      curves.push_back(read_one(zip, names, fmt::format("index/{}/", i), general, shared, origin, options));
  }
  return curves;
}

}  // namespace afmkit::io::curves::detail
