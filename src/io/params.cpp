#include "afmkit/io/params.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/input_file.hpp"
#include "afmkit/io/number.hpp"

namespace afmkit::io {

namespace {
std::string dashed(std::string key) {
  std::replace(key.begin(), key.end(), '_', '-');
  return key;
}

/// The same value, bit for bit (-0.0 is not 0.0; a NaN is itself): reset_values keeps a value that passed check().
bool same_value(const ParamSet::Value& a, const ParamSet::Value& b) {
  if (a.index() != b.index()) return false;
  const auto same_real = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  switch (a.index()) {
    case 0: return same_real(std::get<double>(a), std::get<double>(b));
    case 1: return std::get<long>(a) == std::get<long>(b);
    case 2: return std::get<std::string>(a) == std::get<std::string>(b);
    case 3: return std::get<bool>(a) == std::get<bool>(b);
    default: {
      const auto& x = std::get<std::vector<double>>(a);
      const auto& y = std::get<std::vector<double>>(b);
      return x.size() == y.size() && std::equal(x.begin(), x.end(), y.begin(), same_real);
    }
  }
}

double real_of(const std::string& key, const std::string& text, const std::string& origin, const Range& range) {
  // nan / inf are accepted textually so that the range check rejects them with a clear message
  if (const auto v = parse_real(text)) return *v;
  throw InvalidParameter(key, fmt::format("{}: {} = '{}' is not a number: must be {}", origin, key, text,
                                          range.describe()));
}
/// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points above U+10FFFF).
bool valid_utf8(const std::string& text) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const auto* end = p + text.size();
  while (p < end) {
    const unsigned c = *p;
    int extra = 0;
    unsigned min = 0, code = 0;
    if (c < 0x80) extra = 0, code = c;
    else if ((c & 0xE0) == 0xC0) extra = 1, code = c & 0x1F, min = 0x80;
    else if ((c & 0xF0) == 0xE0) extra = 2, code = c & 0x0F, min = 0x800;
    else if ((c & 0xF8) == 0xF0) extra = 3, code = c & 0x07, min = 0x10000;
    else return false;
    if (end - p <= extra) return false;  // truncated sequence
    for (int i = 1; i <= extra; ++i) {
      if ((p[i] & 0xC0) != 0x80) return false;
      code = (code << 6) | (p[i] & 0x3F);
    }
    if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
    p += extra + 1;
  }
  return true;
}

/// Refuses TOML nested deeper than `max_toml_nesting` levels before toml++ parses it: its parser and its tables
/// recurse once per level of a table header or dotted key (`[a.b.c…]`, `a.b.c… = 1`), so thousands of levels
/// overflow the stack. Counts, outside strings and comments, the open arrays and inline tables plus the parts of the
/// key being read (a table header's or a key's dots); afmkit's parameter files are flat (one level).
constexpr int max_toml_nesting = 100;
void check_toml_nesting(std::string_view text, const std::string& origin) {
  std::vector<char> inside;  // the open arrays '[' and inline tables '{' of values
  int key_parts = 0;         // parts of the key (or table header) being read
  bool in_key = true, header = false;
  long line = 1;
  auto check = [&] {
    if (static_cast<int>(inside.size()) + key_parts > max_toml_nesting)
      throw InputError(fmt::format("{}:{}: TOML nested deeper than {} levels (tables, dotted keys, arrays, inline "
                                   "tables): a parameter file has one level of keys",
                                   origin, line, max_toml_nesting));
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      if (inside.empty()) in_key = true, header = false, key_parts = 0;
      continue;
    }
    if (c == '#') {  // a comment runs to the end of the line
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
      continue;
    }
    if (c == '"' || c == '\'') {  // a string or quoted key, skipped whole (escapes in basic strings)
      const std::string_view triple = c == '"' ? R"(""")" : "'''";
      const std::string_view close = text.substr(i, 3) == triple ? triple : text.substr(i, 1);
      i += close.size();
      while (i < text.size() && text.substr(i, close.size()) != close) {
        if (text[i] == '\n') ++line;
        if (c == '"' && text[i] == '\\') ++i;
        ++i;
      }
      i += close.size() - 1;
      if (in_key && key_parts == 0) key_parts = 1;
      continue;
    }
    if (in_key) {
      if (c == '[' && key_parts == 0 && !header && inside.empty()) {
        header = true;  // [table] or [[array of tables]]
        continue;
      }
      if (c == '.') ++key_parts;
      else if (key_parts == 0 && c != ' ' && c != '\t' && c != '\r' && c != '[' && c != ']' && c != '=') key_parts = 1;
      if (c == '=' || (header && c == ']')) in_key = false;
      check();
      continue;
    }
    if (c == '[' || c == '{') {
      inside.push_back(c);
      if (c == '{') in_key = true, key_parts = 0;  // an inline table's keys
      check();
    } else if ((c == ']' || c == '}') && !inside.empty()) {
      inside.pop_back();
    } else if (c == ',' && !inside.empty() && inside.back() == '{') {
      in_key = true, key_parts = 0;
    }
  }
}
}  // namespace

ParamSet::Entry ParamSet::make_entry(Value value, const std::string& help, Range range) {
  Entry e;
  e.value = std::move(value);
  e.help = help;
  e.range = range;
  return e;
}

std::uint32_t ParamSet::find(std::string_view key) const noexcept {
  static_assert(LookupCache::size == 256, "the slot is the top 8 bits of a product");
  // the index found last time for a key at this address (a literal), confirmed by the key itself
  std::atomic<std::uint32_t>& recent =
      recent_.slots[(reinterpret_cast<std::uintptr_t>(key.data()) * 0x9e3779b97f4a7c15ull) >> 56];
  const std::uint32_t guess = recent.load(std::memory_order_relaxed);
  if (guess < entries_.size() && entries_[guess].key == key) [[likely]]
    return guess;
  return find_by_hash(key, recent);
}
std::uint32_t ParamSet::find_by_hash(std::string_view key, std::atomic<std::uint32_t>& recent) const noexcept {
  const auto it = index_.find(key);
  if (it == index_.end()) return kNone;
  recent.store(it->second, std::memory_order_relaxed);
  return it->second;
}

void ParamSet::declare(const std::string& key, Entry e, const afmkit::SourceLocation& where) {
  e.key = key;
  e.group = group_;
  if (const auto c = group_conditions_.find(group_); c != group_conditions_.end())
    e.applies.push_back({c->second.first, find(c->second.first), {c->second.second}});
  std::uint32_t at = find(key);
  if (at != kNone) {
    e.declared_at = std::move(entries_[at].declared_at);  // declared again: both places are kept (the test names them)
  } else {
    at = static_cast<std::uint32_t>(entries_.size());
    if (at == kNone - 1) throw std::logic_error("ParamSet: too many parameters");
    entries_.emplace_back();
    entries_.back().key = key;
    index_.emplace(key, at);
    by_key_.insert(std::lower_bound(by_key_.begin(), by_key_.end(), key,
                                    [this](std::uint32_t i, const std::string& k) { return entries_[i].key < k; }),
                   at);
    keys_signature_ = (keys_signature_ ^ std::hash<std::string_view>{}(key)) * 0x9e3779b97f4a7c15ull + 1;
  }
  e.declared_at.push_back(fmt::format("{}:{}", where.file_name(), where.line()));
  entries_[at] = std::move(e);
  last_ = at;
}
ParamSet::Entry& ParamSet::last(const char* what) {
  if (last_ == kNone) throw std::logic_error(fmt::format("ParamSet::{} before any parameter", what));
  return entries_[last_];
}
ParamSet& ParamSet::group(const std::string& name) {
  group_ = name;
  return *this;
}
ParamSet& ParamSet::group(const std::string& name, const std::string& when_key, const std::string& when_value) {
  group_ = name;
  group_conditions_[name] = {when_key, when_value};
  return *this;
}

namespace {
/// --help formatter that leaves out the groups whose condition (a text option's value) does not hold.
class ConditionalGroupFormatter : public CLI::Formatter {
 public:
  struct Condition {
    std::string option, value, default_value;
  };
  ConditionalGroupFormatter(const CLI::App* app, std::map<std::string, Condition> conditions)
      : app_(app), conditions_(std::move(conditions)) {}
  std::string make_group(std::string group, bool is_positional, std::vector<const CLI::Option*> opts) const override {
    if (const auto it = conditions_.find(group); it != conditions_.end()) {
      const CLI::Option* opt = app_->get_option_no_throw(it->second.option);
      const std::string current =
          opt && !opt->results().empty() ? opt->results().back() : it->second.default_value;
      if (current != it->second.value) return {};
    }
    return CLI::Formatter::make_group(std::move(group), is_positional, std::move(opts));
  }

 private:
  const CLI::App* app_;
  std::map<std::string, Condition> conditions_;
};
}  // namespace
ParamSet& ParamSet::default_text(const std::string& text) {
  last("default_text").default_text = text;
  return *this;
}
ParamSet& ParamSet::follows(const std::string& key) {
  Entry& e = last("follows");
  const std::uint32_t at = find(key);
  if (at == kNone || at == last_)
    throw std::logic_error(fmt::format("ParamSet::follows: '{}' follows '{}', which is not declared before it", e.key, key));
  if (entries_[at].value.index() != e.value.index())
    throw std::logic_error(fmt::format("ParamSet::follows: '{}' and '{}' are not of the same kind", e.key, key));
  e.follows = key;
  e.follows_at = at;
  if (e.default_text.empty()) e.default_text = "= " + key;
  return *this;
}
ParamSet& ParamSet::only_if_given(std::vector<std::string> instead_of) {
  Entry& e = last("only_if_given");
  e.only_if_given = true;
  e.instead_of = std::move(instead_of);
  return *this;
}
ParamSet& ParamSet::applies_when(const std::string& param, const std::string& key, std::vector<std::string> values) {
  const std::uint32_t it = find(param);
  const std::uint32_t on = find(key);
  if (it == kNone || on == kNone || !std::holds_alternative<std::string>(entries_[on].value))
    throw std::logic_error(fmt::format("ParamSet::applies_when: '{}' or the text parameter '{}' is not declared",
                                       param, key));
  entries_[it].applies.push_back({key, on, std::move(values)});
  return *this;
}
ParamSet& ParamSet::applies_if(const std::string& param, std::function<bool(const ParamSet&)> condition) {
  const std::uint32_t it = find(param);
  if (it == kNone || !condition)
    throw std::logic_error(fmt::format("ParamSet::applies_if: '{}' is not declared or has no condition", param));
  entries_[it].applies_if.push_back(std::move(condition));
  return *this;
}
ParamSet& ParamSet::recorded_only_if_given(const std::string& param) {
  const std::uint32_t it = find(param);
  if (it == kNone)
    throw std::logic_error(fmt::format("ParamSet::recorded_only_if_given: '{}' is not declared", param));
  entries_[it].only_if_given = true;
  return *this;
}
void ParamSet::record_used(const std::string& key, Value value) {
  const std::uint32_t it = find(key);
  if (it == kNone) throw std::logic_error("ParamSet::record_used: no parameter named '" + key + "'");
  Entry& e = entries_[it];
  if (std::holds_alternative<double>(e.value) && std::holds_alternative<long>(value))
    value = static_cast<double>(std::get<long>(value));
  if (value.index() != e.value.index())
    throw std::logic_error(fmt::format("ParamSet::record_used: '{}' recorded with a value of another kind", key));
  e.value = std::move(value);
  e.used = true;
  e.checked = false;
  check(key, e, "");
  e.checked = true;
}
ParamSet& ParamSet::positional() {
  if (last_ == kNone || !std::holds_alternative<std::string>(entries_[last_].value))
    throw std::logic_error("ParamSet::positional: the last declared parameter is not a text or file");
  for (std::uint32_t i = 0; i < entries_.size(); ++i)
    if (entries_[i].positional && i != last_)
      throw std::logic_error("ParamSet::positional: only one positional parameter");
  entries_[last_].positional = true;
  return *this;
}
ParamSet& ParamSet::unit(const std::string& unit) {
  Entry& e = last("unit");
  if (std::holds_alternative<std::string>(e.value) || std::holds_alternative<bool>(e.value))
    throw std::logic_error(fmt::format("ParamSet::unit: '{}' is not a number", e.key));
  e.unit = unit;
  return *this;
}
const std::string& ParamSet::unit_of(std::string_view key) const& { return entry(key).unit; }
ParamSet& ParamSet::real(const std::string& key, double def, const std::string& help, Range range,
                         afmkit::SourceLocation where) {
  declare(key, make_entry(def, help, range), where);
  return *this;
}
ParamSet& ParamSet::integer(const std::string& key, long def, const std::string& help, long lo, long hi,
                            afmkit::SourceLocation where) {
  Entry e = make_entry(def, help, Range::any());
  e.unit = "count";  // a number of things, unless unit() says otherwise
  e.ilo = lo;
  e.ihi = hi;
  declare(key, std::move(e), where);
  return *this;
}
ParamSet& ParamSet::text(const std::string& key, const std::string& def, const std::string& help,
                         std::vector<std::string> choices, afmkit::SourceLocation where) {
  Entry e = make_entry(def, help, Range::any());
  e.choices = std::move(choices);
  declare(key, std::move(e), where);
  return *this;
}
ParamSet& ParamSet::file(const std::string& key, const std::string& def, const std::string& help,
                         afmkit::SourceLocation where) {
  text(key, def, help, {}, where);
  entries_[last_].is_file = true;
  // in declaration order (check_files reports the first clash in that order)
  if (const auto at = std::lower_bound(files_.begin(), files_.end(), last_); at == files_.end() || *at != last_)
    files_.insert(at, last_);
  return *this;
}
ParamSet& ParamSet::flag(const std::string& key, bool def, const std::string& help, afmkit::SourceLocation where) {
  declare(key, make_entry(def, help, Range::any()), where);
  return *this;
}
ParamSet& ParamSet::reals(const std::string& key, std::vector<double> def, const std::string& help, Range range,
                          afmkit::SourceLocation where) {
  declare(key, make_entry(std::move(def), help, range), where);
  return *this;
}

void ParamSet::add_options(CLI::App& app) {
  if (!group_conditions_.empty()) {
    std::map<std::string, ConditionalGroupFormatter::Condition> conditions;
    for (const auto& [group, condition] : group_conditions_) {
      const Entry& e = std::as_const(*this).entry(condition.first);
      conditions[group] = {"--" + dashed(condition.first), condition.second, std::get<std::string>(e.value)};
    }
    app.formatter(std::make_shared<ConditionalGroupFormatter>(&app, std::move(conditions)));
  }
  app.add_option("--config", config_path_, "TOML file with parameters (keys as below, with underscores)")
      ->type_name("FILE");
  for (Entry& e : entries_) {  // (the callbacks below keep &e: entries stay where they are)
    const std::string& key = e.key;
    std::string desc = e.help;
    std::string type;
    auto shown = [&](const auto& value) { return e.default_text.empty() ? fmt::format("{}", value) : e.default_text; };
    const bool numeric = !std::holds_alternative<std::string>(e.value) && !std::holds_alternative<bool>(e.value);
    if (numeric && e.unit.empty())  // every number a user sees carries its unit (docs/units.md)
      throw std::logic_error(fmt::format("ParamSet: parameter '{}' is declared without a unit", key));
    std::visit(
        [&](const auto& v) {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, double>) {
            type = "FLOAT";
            desc += fmt::format(" [unit: {}; default {}; {}]", e.unit, shown(v), e.range.describe());
          } else if constexpr (std::is_same_v<T, long>) {
            type = "INT";
            desc += fmt::format(" [unit: {}; default {}; integer in [{}, {}]]", e.unit, shown(v), e.ilo, e.ihi);
          } else if constexpr (std::is_same_v<T, std::string>) {
            type = e.is_file ? "FILE" : e.choices.empty() ? "TEXT" : "NAME";
            desc += fmt::format(" [default {}{}]", e.default_text.empty() ? "'" + v + "'" : e.default_text,
                                e.choices.empty() ? "" : fmt::format("; one of {}", fmt::join(e.choices, ", ")));
          } else if constexpr (std::is_same_v<T, bool>) {
            desc += fmt::format(" [default {}]", e.default_text.empty() ? (v ? "on" : "off") : e.default_text);
          } else {
            type = "FLOAT,...";
            desc += fmt::format(" [unit: {}; default {}; comma-separated, each {}]", e.unit,
                                e.default_text.empty() ? fmt::format("{}", fmt::join(v, ",")) : e.default_text,
                                e.range.describe());
          }
        },
        e.value);
    CLI::Option* opt =
        app.add_option_function<std::string>("--" + dashed(key), [&e](const std::string& s) { e.cli_text = s; }, desc);
    // a flag (empty type): `--json` turns it on, `--json=false` off (TOML: json = true / false)
    if (type.empty()) opt->expected(0, 1);
    opt->type_name(type)->group(e.group);
    if (e.positional) {
      CLI::Option* pos = app.add_option_function<std::string>(
          key, [&e](const std::string& s) { e.cli_text = s; }, fmt::format("the same as --{}", dashed(key)));
      pos->type_name(type)->excludes(opt);
    }
  }
}

void ParamSet::check(const std::string& key, const Entry& e, const std::string& origin) const {
  std::visit(
      [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, double>) {
          if (!e.range.contains(v))
            throw InvalidParameter(key, fmt::format("{}{}{} = {} is out of range: must be {}", origin,
                                                    origin.empty() ? "" : ": ", key, v, e.range.describe()));
        } else if constexpr (std::is_same_v<T, long>) {
          if (v < e.ilo || v > e.ihi)
            throw InvalidParameter(key, fmt::format("{}{}{} = {} is out of range: must be an integer in [{}, {}]",
                                                    origin, origin.empty() ? "" : ": ", key, v, e.ilo, e.ihi));
        } else if constexpr (std::is_same_v<T, std::string>) {
          if (e.is_file && v.find('\0') != std::string::npos)  // the C library would cut the path there
            throw InvalidParameter(key, fmt::format("{}{}{} holds a NUL character (\\0): a path cannot contain one",
                                                    origin, origin.empty() ? "" : ": ", key));
          if (!e.choices.empty() && std::find(e.choices.begin(), e.choices.end(), v) == e.choices.end())
            throw InvalidParameter(key, fmt::format("{}{}{} = '{}' is not allowed: must be one of {}", origin,
                                                    origin.empty() ? "" : ": ", key, v, fmt::join(e.choices, ", ")));
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          for (double x : v)
            if (!e.range.contains(x))
              throw InvalidParameter(key, fmt::format("{}{}{} contains {}: every entry must be {}", origin,
                                                      origin.empty() ? "" : ": ", key, x, e.range.describe()));
        }
      },
      e.value);
}

void ParamSet::set_from_string(const std::string& key, const std::string& text) {
  const std::uint32_t it = find(key);
  if (it == kNone) throw InputError(fmt::format("unknown parameter '{}'", key));
  Entry& e = entries_[it];
  e.checked = false;
  const std::string origin = "--" + dashed(key);
  std::visit(
      [&](auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, double>) {
          v = real_of(key, text, origin, e.range);
        } else if constexpr (std::is_same_v<T, long>) {
          const auto i = parse_integer(text);
          if (!i)
            throw InvalidParameter(key, fmt::format("{}: {} = '{}' is not an integer: must be an integer in [{}, {}]",
                                                    origin, key, text, e.ilo, e.ihi));
          v = *i;
        } else if constexpr (std::is_same_v<T, std::string>) {
          if (!valid_utf8(text))
            throw InvalidParameter(key, fmt::format("{}: {} is not valid UTF-8 text: must be UTF-8", origin, key));
          v = text;
        } else if constexpr (std::is_same_v<T, bool>) {
          if (text == "true" || text == "1" || text.empty()) v = true;
          else if (text == "false" || text == "0") v = false;
          else throw InvalidParameter(key, fmt::format("{}: {} = '{}' must be true or false", origin, key, text));
        } else {
          std::vector<double> out;
          std::stringstream ss(text);
          std::string item;
          while (std::getline(ss, item, ',')) out.push_back(real_of(key, item, origin, e.range));
          v = out;
        }
      },
      e.value);
  e.set = true;
  check(key, e, "");
  e.checked = true;
}

namespace {
/// The keys of `entries` in declaration order (messages naming the keys allowed).
template <class Entries>
std::vector<std::string> keys_of(const Entries& entries) {
  std::vector<std::string> out;
  out.reserve(entries.size());
  for (const auto& e : entries) out.push_back(e.key);
  return out;
}
}  // namespace

void ParamSet::set_value(const std::string& key, Value value, const std::string& origin) {
  const std::uint32_t it = find(key);
  if (it == kNone)
    throw InputError(fmt::format("{}{}unknown parameter '{}' (allowed: {})", origin, origin.empty() ? "" : ": ", key,
                                 fmt::join(keys_of(entries_), ", ")));
  Entry& e = entries_[it];
  if (std::holds_alternative<double>(e.value) && std::holds_alternative<long>(value))
    value = static_cast<double>(std::get<long>(value));
  if (value.index() != e.value.index()) {
    static constexpr const char* want[] = {"a number", "an integer", "a string", "true or false", "a list of numbers"};
    throw InvalidParameter(key, fmt::format("{}{}{} must be {}", origin, origin.empty() ? "" : ": ", key,
                                            want[e.value.index()]));
  }
  e.value = std::move(value);
  e.set = true;
  e.checked = false;
  check(key, e, origin);
  e.checked = true;
}

void ParamSet::reset_values(const ParamSet& declared) {
  // the same keys in the same order (a copy of `declared`): compared by their signature, not key by key
  if (entries_.size() != declared.entries_.size() || keys_signature_ != declared.keys_signature_)
    throw std::logic_error("ParamSet::reset_values: another set of parameters");
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    Entry& e = entries_[i];
    const Entry& d = declared.entries_[i];
    const double* x = std::get_if<double>(&e.value);
    const double* y = std::get_if<double>(&d.value);
    const bool same = x && y ? std::memcmp(x, y, sizeof(double)) == 0 : same_value(e.value, d.value);
    if (!same) {  // a value the last run changed; one kept stays checked (resolve)
      e.value = d.value;                  // a text keeps its buffer
      e.checked = d.checked;
    }
    e.set = d.set;
    if (e.cli_text || d.cli_text) e.cli_text = d.cli_text;
    e.used = d.used;
  }
  config_path_ = declared.config_path_;
}

std::vector<ParamSet::Description> ParamSet::describe() const {
  std::vector<Description> out;
  for (const Entry& e : entries_) {
    const std::string& key = e.key;
    Description d{key, "", e.value, e.default_text, e.help, e.unit, "", e.group, e.choices, e.follows, e.declared_at};
    switch (e.value.index()) {
      case 0: d.kind = "real"; d.allowed = e.range.describe(); break;
      case 1: d.kind = "integer"; d.allowed = fmt::format("integer in [{}, {}]", e.ilo, e.ihi); break;
      case 2:
        d.kind = e.is_file ? "file" : "text";
        if (!e.choices.empty()) d.allowed = fmt::format("one of {}", fmt::join(e.choices, ", "));
        break;
      case 3: d.kind = "flag"; d.unit.clear(); break;
      default: d.kind = "reals"; d.allowed = "each " + e.range.describe(); break;
    }
    if (d.kind == "text" || d.kind == "file") d.unit.clear();
    out.push_back(std::move(d));
  }
  return out;
}

void ParamSet::set_default(const std::string& key, const std::string& text) {
  set_from_string(key, text);
  entry(key).set = false;
}

namespace {
/// The `parameters` of a JSON sidecar (io::make_sidecar) as a TOML table: the record of a run given as --config
/// replays it. InputError naming the file when it is not a sidecar.
toml::table sidecar_parameters(const std::string& text, const std::string& origin) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(fmt::format("{}: malformed JSON (a JSON config file must be the sidecar of a run): {}", origin,
                                 e.what()));
  }
  const auto params = doc.is_object() ? doc.find("parameters") : doc.end();
  if (params == doc.end() || !params->is_object())
    throw InputError(fmt::format("{}: a JSON config file must be the sidecar of a run (an object with a "
                                 "\"parameters\" object); give parameters as TOML otherwise",
                                 origin));
  toml::table tbl;
  for (const auto& item : params->items()) {
    const std::string key = item.key();  // not a structured binding: clang 14 cannot capture those in a lambda
    const nlohmann::json& v = item.value();
    const auto no_value = [&] {
      throw InvalidParameter(key, fmt::format("{}: key '{}' = {} is not a parameter value", origin, key, v.dump()));
    };
    if (v.is_boolean()) tbl.insert(key, v.get<bool>());
    else if (v.is_number_integer() && !(v.is_number_unsigned() && v.get<std::uint64_t>() > INT64_MAX))
      tbl.insert(key, v.get<std::int64_t>());
    else if (v.is_number()) tbl.insert(key, v.get<double>());
    else if (v.is_string()) tbl.insert(key, v.get<std::string>());
    else if (v.is_array()) {
      toml::array a;
      for (const auto& x : v) {
        if (!x.is_number()) no_value();
        a.push_back(x.get<double>());
      }
      tbl.insert(key, std::move(a));
    } else {
      no_value();
    }
  }
  return tbl;
}
}  // namespace

void ParamSet::load_toml_text(const std::string& text, const std::string& origin) {
  toml::table tbl;
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '{') {  // a sidecar (a TOML document cannot start with '{')
    tbl = sidecar_parameters(text, origin);
  } else {
    check_toml_nesting(text, origin);
    try {
      tbl = toml::parse(text, origin);
    } catch (const toml::parse_error& err) {
      const auto& b = err.source().begin;
      throw InputError(fmt::format("{}:{}:{}: malformed TOML: {}", origin, b.line, b.column, err.description()));
    }
  }
  for (auto&& item : tbl) {  // (no structured binding: clang 14 cannot capture one in the lambda below)
    const std::string key(item.first.str());
    const toml::node& node = item.second;
    const std::uint32_t it = find(key);
    if (it == kNone)
      throw InputError(fmt::format("{}: unknown key '{}' (allowed keys: {})", origin, key,
                                   fmt::join(keys_of(entries_), ", ")));
    Entry& e = entries_[it];
    e.checked = false;
    auto type_error = [&](const char* want) {
      throw InvalidParameter(key, fmt::format("{}: key '{}' must be {}", origin, key, want));
    };
    std::visit(
        [&](auto& v) {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, double>) {
            if (auto d = node.value<double>()) v = *d;
            else type_error("a number");
          } else if constexpr (std::is_same_v<T, long>) {
            // an integer node, or a float with an exact integer value below 2^63 (as "1e7" on the command line);
            // toml++'s own float-to-integer conversion casts before it checks the range (UB, found by fuzzing)
            if (const auto* i = node.as_integer()) {
              v = static_cast<long>(i->get());
            } else if (const auto* f = node.as_floating_point();
                       f && std::isfinite(f->get()) && std::trunc(f->get()) == f->get() && std::abs(f->get()) < 0x1p63) {
              v = static_cast<long>(f->get());
            } else {
              type_error("an integer");
            }
          } else if constexpr (std::is_same_v<T, std::string>) {
            if (auto s = node.value<std::string>()) v = *s;
            else type_error("a string");
          } else if constexpr (std::is_same_v<T, bool>) {
            if (auto b = node.value<bool>()) v = *b;
            else type_error("true or false");
          } else {
            const toml::array* arr = node.as_array();
            if (!arr) type_error("an array of numbers");
            std::vector<double> out;
            for (auto&& el : *arr) {
              auto d = el.value<double>();
              if (!d) type_error("an array of numbers");
              out.push_back(*d);
            }
            v = out;
          }
        },
        e.value);
    e.set = true;
    check(key, e, origin);
    e.checked = true;
  }
}

void ParamSet::resolve() {
  if (!config_path_.empty()) {
    if (config_path_.find('\0') != std::string::npos)
      throw InvalidParameter("config", "config holds a NUL character (\\0): a path cannot contain one");
    constexpr std::uintmax_t max_config_bytes = 16u << 20;  // a parameter file, not data
    load_toml_text(files::read_input_file(config_path_, "--config file", max_config_bytes), config_path_);
  }
  // in declaration order (the first flag, else the first value refused is the one reported); a value that passed
  // check() since it last changed is not checked again: a front end that resets a set and resolves it per call (the
  // Python module: reset_values keeps the values the last call did not change) checks only the few values given
  for (Entry& e : entries_)
    if (e.cli_text) set_from_string(e.key, *e.cli_text);  // checks it
  for (Entry& e : entries_) {
    if (!e.checked) {
      check(e.key, e, "");
      e.checked = true;
    }
  }
  check_files();
}

const ParamSet::Entry& ParamSet::entry(std::string_view key) const {
  const std::uint32_t at = find(key);
  if (at == kNone) throw std::logic_error("ParamSet: no parameter named '" + std::string(key) + "'");
  return entries_[at];
}
ParamSet::Entry& ParamSet::entry(std::string_view key) {
  return const_cast<Entry&>(std::as_const(*this).entry(key));
}
const ParamSet::Entry& ParamSet::current_at(std::uint32_t at) const {
  const Entry* e = &entries_[at];
  // a chain of follows ends: each followed key is declared before its follower
  while (!e->set && !e->used && e->follows_at != kNone) e = &entries_[e->follows_at];
  return *e;
}
const ParamSet::Entry& ParamSet::current(std::string_view key) const {
  const std::uint32_t at = find(key);
  if (at == kNone) throw std::logic_error("ParamSet: no parameter named '" + std::string(key) + "'");
  const Entry* e = &entries_[at];  // (current_at's loop, without a call: ~100 values read per command call)
  while (!e->set && !e->used && e->follows_at != kNone) e = &entries_[e->follows_at];
  return *e;
}
std::vector<std::string_view> ParamSet::replaced() const {
  std::vector<std::string_view> out;  // few: only_if_given alternatives that were given
  for (const Entry& o : entries_)
    if (o.only_if_given && o.set) out.insert(out.end(), o.instead_of.begin(), o.instead_of.end());
  return out;
}
bool ParamSet::recorded(const Entry& e, const std::vector<std::string_view>& replaced) const {
  if (e.only_if_given && !e.set) return false;
  for (const Applies& a : e.applies) {  // a key of another unit system or law than the run's
    const Entry* on = a.at != kNone ? &entries_[a.at] : &current(a.key);
    while (!on->set && !on->used && on->follows_at != kNone) on = &entries_[on->follows_at];  // (current_at)
    const std::string& value = std::get<std::string>(on->value);
    if (std::none_of(a.values.begin(), a.values.end(), [&](const std::string& v) { return v == value; }))
      return false;
  }
  for (const auto& condition : e.applies_if)  // a key of another controller than the run's
    if (!condition(*this)) return false;
  // given, an alternative stands for these keys (only_if_given(instead_of))
  return std::find(replaced.begin(), replaced.end(), std::string_view(e.key)) == replaced.end();
}
double ParamSet::real(std::string_view key) const { return std::get<double>(current(key).value); }
long ParamSet::integer(std::string_view key) const { return std::get<long>(current(key).value); }
const std::string& ParamSet::text(std::string_view key) const& { return std::get<std::string>(current(key).value); }
bool ParamSet::flag(std::string_view key) const { return std::get<bool>(current(key).value); }
const std::vector<double>& ParamSet::reals(std::string_view key) const& {
  return std::get<std::vector<double>>(current(key).value);
}
bool ParamSet::was_set(std::string_view key) const {
  const std::uint32_t at = find(key);
  if (at == kNone) throw std::logic_error("ParamSet: no parameter named '" + std::string(key) + "'");
  return entries_[at].set;
}

nlohmann::json ParamSet::units_json() const {
  nlohmann::json j = nlohmann::json::object();
  const std::vector<std::string_view> gone = replaced();
  for (const Entry& e : entries_)
    if (!e.unit.empty() && recorded(e, gone)) j[e.key] = e.unit;
  return j;
}

nlohmann::json ParamSet::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  // the values the run used: a key that follows another records the followed value, a value recorded by
  // record_used replaces the default, an alternative not given is left out (params.hpp)
  // in the keys' order (entries_ and the JSON object sort them alike): each added at the end, no lookups
  const std::vector<std::string_view> gone = replaced();
  auto& object = j.get_ref<nlohmann::json::object_t&>();
  for (const std::uint32_t at : by_key_) {
    const Entry& e = entries_[at];
    const bool conditional = e.only_if_given || !e.applies.empty() || !e.applies_if.empty() || !gone.empty();
    if (conditional && !recorded(e, gone)) continue;
    const std::string& key = e.key;
    const Entry& used = current_at(at);
    std::visit([&](const auto& v) { object.emplace_hint(object.end(), key, v); }, used.value);
  }
  return j;
}

}  // namespace afmkit::io
