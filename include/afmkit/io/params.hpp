#pragma once
// ParamSet: the named, typed, range-checked parameters of one command. Values come from (in increasing
// priority) the built-in default, a TOML file given with --config, and command-line flags.
//   TOML key  `quality_factor = 400`      <->  flag `--quality-factor 400`
// Unknown TOML keys, malformed TOML, a missing file, a wrong type or a value out of range raise
// afmkit::InputError / afmkit::InvalidParameter naming the key (or file) and the allowed range.
#include <cstdint>
#include <algorithm>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include "afmkit/core/source_location.hpp"
#include <string>
#include <string_view>
#include <unordered_map>
#include <variant>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "afmkit/core/range.hpp"

namespace CLI {
class App;
}

namespace afmkit::io {

/// Allowed range of a numeric parameter (core/range.hpp: the same type the library's option descriptions use).
using Range = afmkit::Range;

/// What an output parameter's value writes (ParamSet::writes): a file, or a folder whose whole content counts as
/// written (a store replaced as a whole).
struct WrittenPath {
  std::string path;
  bool folder = false;
};
using WrittenPaths = std::function<std::vector<WrittenPath>(const std::string& value)>;
/// A table's files: `path` and its sidecar `<path>.json` (io::TableWriter).
std::vector<WrittenPath> table_and_sidecar(const std::string& path);

class ParamSet {
 public:
  using Value = std::variant<double, long, std::string, bool, std::vector<double>>;

  // Declaring a parameter. Each records where it is declared (`where`, the caller's line by default: see
  // Description::declared_at): a key is declared in one place, shared by the commands that have it (a function
  // such as add_tapping_model_params, or a library struct's describe(): apps/described_params.hpp);
  // tests/cli/test_declared_once.cpp checks it over every command.
  ParamSet& real(const std::string& key, double def, const std::string& help, Range range = Range::any(),
                 afmkit::SourceLocation where = afmkit::SourceLocation::current());
  ParamSet& integer(const std::string& key, long def, const std::string& help, long lo, long hi,
                    afmkit::SourceLocation where = afmkit::SourceLocation::current());
  ParamSet& text(const std::string& key, const std::string& def, const std::string& help,
                 std::vector<std::string> choices = {},
                 afmkit::SourceLocation where = afmkit::SourceLocation::current());
  /// A file path (a text shown as FILE in --help).
  ParamSet& file(const std::string& key, const std::string& def, const std::string& help,
                 afmkit::SourceLocation where = afmkit::SourceLocation::current());
  ParamSet& flag(const std::string& key, bool def, const std::string& help,
                 afmkit::SourceLocation where = afmkit::SourceLocation::current());
  /// A list of reals: TOML array, or a comma-separated flag value "1,0.5,0.2".
  ParamSet& reals(const std::string& key, std::vector<double> def, const std::string& help,
                  Range range = Range::any(), afmkit::SourceLocation where = afmkit::SourceLocation::current());
  /// Parameters declared after this call are listed under `name` in --help (model, drive, contact law, numerics,
  /// output, …); before any call: "Options".
  ParamSet& group(const std::string& name);
  /// A group that applies only when the text parameter `when_key` has the value `when_value` (e.g. the physical
  /// model keys when units = physical): --help lists it only then (judged from the flags given with --help, else
  /// the default); its keys are still accepted (the command decides whether they conflict).
  ParamSet& group(const std::string& name, const std::string& when_key, const std::string& when_value);
  /// What --help shows as the default of the last declared parameter when it is not a fixed value ("automatic",
  /// "= plant_rate", …); the declared default stays the value used when nothing else applies.
  ParamSet& default_text(const std::string& text);
  /// The last declared parameter, when not given, takes the value of parameter `key` (declared before it, of the
  /// same kind): value(), real(), … and the records (to_json: sidecars, Python r.params) give the value the run
  /// used. --help shows "= key" unless default_text() says otherwise.
  ParamSet& follows(const std::string& key);
  /// The last declared parameter counts only when given (an alternative, e.g. restitution instead of
  /// departure_stiffness): not given, it is left out of the records; given, it stands for the keys `instead_of`,
  /// which are then left out of the records (a replay gives the alternative, as the run did).
  ParamSet& only_if_given(std::vector<std::string> instead_of = {});
  /// Parameter `param` (declared before) counts only when given, as only_if_given(): for a shared key that a
  /// command refuses when given (it does not apply there), so that its records never list it.
  ParamSet& recorded_only_if_given(const std::string& param);
  /// Parameter `param` (declared before) applies only when the text parameter `key` has one of `values` (a key of
  /// one unit system, of some force laws): otherwise the run did not use it and it is left out of the records
  /// (to_json: sidecars, Python r.params; units_json), so that a record lists exactly the parameters that applied
  /// and replays as given. Conditions add up (all must hold). A parameter declared in a group with a condition
  /// (group(name, when_key, when_value)) has that condition.
  ParamSet& applies_when(const std::string& param, const std::string& key, std::vector<std::string> values);
  /// Parameter `param` (declared before) applies only when `condition` holds of the run's values: a rule
  /// applies_when cannot say (one of two keys decides, e.g. the controller, or the Smith predictor's inner
  /// controller when the controller is the Smith predictor). Otherwise as applies_when: left out of the records.
  ParamSet& applies_if(const std::string& param, std::function<bool(const ParamSet&)> condition);
  /// Records the value a run used for a parameter whose value the command computes or chooses itself
  /// ("automatic", "proven bound", a default that depends on other values): value() and the records give it from
  /// now on; it does not count as given (was_set). Validated as a given value is (InvalidParameter naming the key).
  void record_used(const std::string& key, Value value);
  /// The unit of the last declared number (docs/units.md: "nm", "rad", "dimensionless", "units of Omega", …),
  /// shown in --help and written to sidecars. Every real parameter needs one (add_options throws
  /// std::logic_error otherwise); integers default to "count".
  ParamSet& unit(const std::string& unit);
  /// The last declared text or file parameter may also be given as the command's first positional argument
  /// (`afmkit study run FILE`); the flag and TOML key stay.
  ParamSet& positional();
  /// The last declared file parameter is written (an output), not read; `paths` lists what a value writes (default:
  /// the file itself). Every other file parameter, and --config, is read. See check_files().
  ParamSet& writes(WrittenPaths paths = {});
  /// Refuses, before anything is computed, an output that would replace an input or another output: every path an
  /// output writes is compared with every input (the same file through a symbolic or hard link: st_dev/st_ino; a
  /// path that does not exist yet: by canonical path; inside a written folder) and with the other outputs; and a
  /// file output that cannot be written where it is named (an existing folder, FIFO or device; a path under a
  /// file). InvalidParameter naming the output. resolve() calls it; a front end that sets values
  /// after resolve() calls it again.
  void check_files() const;
  const std::string& unit_of(std::string_view key) const&;

  /// Adds `--config FILE` and one `--<key-with-dashes>` option per parameter to `app`.
  void add_options(CLI::App& app);
  /// Call after parsing: loads --config (if any), applies flags, validates. Throws on bad input.
  void resolve();
  /// Load values from TOML text (used by resolve() and by tests). `origin` names the source in messages. A JSON
  /// sidecar of a run (text starting with '{': its "parameters" object) is read as the same keys, so that
  /// `--config out.csv.json` replays the run it records.
  void load_toml_text(const std::string& text, const std::string& origin);
  /// Change the default of a registered parameter (textual form, validated); it still counts as "not set".
  void set_default(const std::string& key, const std::string& text);
  /// Set one value from its textual form (as a flag would), validating it.
  void set_from_string(const std::string& key, const std::string& text);
  /// Set one value given typed (the Python module), validated as a TOML value is; `origin` prefixes messages ("" for
  /// none). An integer is accepted for a real. InvalidParameter naming the key: wrong type or out of range;
  /// InputError: unknown key.
  void set_value(const std::string& key, Value value, const std::string& origin = "");
  /// A TOML file to load at resolve() (what --config does).
  void set_config_path(const std::string& path) { config_path_ = path; }
  /// The values of `declared` again (as given, defaults, config path), the declarations kept: what copying
  /// `declared` gives when this set has its declarations (a copy of it reused), without copying hundreds of help
  /// texts, choices and ranges again (the Python module reuses a command's sets: bench/command_layer.py).
  /// std::logic_error when the declared keys differ (the same keys, declared in the same order).
  void reset_values(const ParamSet& declared);

  /// One parameter as --help describes it, for other front ends (Python signatures and docstrings).
  struct Description {
    std::string key;
    std::string kind;  ///< real, integer, text, file, flag, reals
    Value default_value;
    std::string default_text;  ///< shown instead of default_value when not empty ("automatic", …)
    std::string help;
    std::string unit;     ///< numbers only
    std::string allowed;  ///< range or choices in words ("> 0", "integer in [1, 100]", "one of a, b")
    std::string group;
    std::vector<std::string> choices;
    std::string follows;  ///< not empty: not given, the parameter takes the value of this one (follows())
    /// Where it is declared ("file:line" of the declaring call), one entry per declaration (a key declared twice
    /// in one set has two).
    std::vector<std::string> declared_at;
  };
  /// Every parameter in declaration order.
  std::vector<Description> describe() const;
  /// The value of any parameter.
  /// (Lookups by key take a std::string_view: a key given as a literal is not copied into a std::string first, and
  /// a key is found by its hash, without comparing it with other keys: the command layer reads ~100 values per call.)
  const Value& value(std::string_view key) const& { return current(key).value; }

  double real(std::string_view key) const;
  long integer(std::string_view key) const;
  const std::string& text(std::string_view key) const&;
  std::string text(std::string_view key) const&& { return text(key); }  // a temporary gives a copy
  bool flag(std::string_view key) const;
  const std::vector<double>& reals(std::string_view key) const&;
  std::vector<double> reals(std::string_view key) const&& { return reals(key); }
  bool was_set(std::string_view key) const;  ///< given by TOML or flag (not the default)

  /// All parameters and their values, for the JSON sidecar.
  nlohmann::json to_json() const;
  /// The unit of every numeric parameter (key -> unit), for the JSON sidecar.
  nlohmann::json units_json() const;
  /// Path given with --config ("" if none).
  const std::string& config_path() const& { return config_path_; }
  std::string config_path() const&& { return config_path_; }

 private:
  static constexpr std::uint32_t kNone = UINT32_MAX;
  /// A condition of applies_when (or of a group with a condition): the text parameter `key` has one of `values`.
  struct Applies {
    std::string key;
    std::uint32_t at = kNone;  // index of `key` in entries_ (kNone: not declared yet when the condition was made)
    std::vector<std::string> values;
  };
  struct Entry {
    std::string key;
    Value value;
    std::string help;
    Range range;
    long ilo = 0, ihi = 0;
    std::vector<std::string> choices;
    bool set = false;
    bool checked = false;                 // the value passed check() since it last changed (resolve skips it)
    std::optional<std::string> cli_text;  // raw flag text captured by CLI11
    std::string group;                    // heading in --help
    std::string default_text;             // shown instead of the value in --help, if set
    std::string unit;                     // numbers only (docs/units.md)
    bool is_file = false;                 // a path: FILE in --help
    bool positional = false;              // also accepted as a positional argument
    bool written = false;                 // a file parameter that is an output (writes())
    WrittenPaths written_paths;           // what its value writes (empty: the file itself)
    std::string follows;                  // not given: the value of this parameter
    std::uint32_t follows_at = kNone;     // its index in entries_ (declared before)
    bool only_if_given = false;           // not given: not recorded
    std::vector<std::string> instead_of;  // given: these parameters are not recorded
    bool used = false;                    // value recorded by record_used
    std::vector<Applies> applies;         // applies_when
    std::vector<std::function<bool(const ParamSet&)>> applies_if;  // applies_if
    std::vector<std::string> declared_at;  // "file:line" of each declaration (Description::declared_at)
  };
  void check(const std::string& key, const Entry& e, const std::string& origin) const;
  /// Index of `key` in entries_, kNone if not declared: the index last found at the key's address (recent_), else
  /// the index_'s.
  [[gnu::always_inline]] inline std::uint32_t find(std::string_view key) const noexcept;
  std::uint32_t find_by_hash(std::string_view key, std::atomic<std::uint32_t>& recent) const noexcept;
  const Entry& entry(std::string_view key) const;
  Entry& entry(std::string_view key);
  /// The entry whose value entries_[at] has now: its own, or (not given, following another key) the followed one's.
  const Entry& current_at(std::uint32_t at) const;
  const Entry& current(std::string_view key) const;
  /// The keys that alternatives given stand for (only_if_given(instead_of)): left out of the records. Computed
  /// once per record, not once per key.
  std::vector<std::string_view> replaced() const;
  /// Whether `e` goes into the records (to_json, units_json).
  bool recorded(const Entry& e, const std::vector<std::string_view>& replaced) const;
  Entry& last(const char* what);
  /// The parameters in declaration order, each on the heap: an entry keeps its address when others are declared
  /// after it and when the set is moved (add_options' callbacks hold it); a copy copies every entry (a copied set
  /// has its own). Elsewhere entries are named by index, never by pointer, so that the default copy and move of
  /// ParamSet give a set that answers from its own entries.
  class Entries {
   public:
    Entries() = default;
    Entries(const Entries& other) { *this = other; }
    Entries& operator=(const Entries& other) {
      if (this == &other) return *this;
      items_.resize(std::min(items_.size(), other.items_.size()));
      for (std::size_t i = 0; i < items_.size(); ++i) *items_[i] = *other.items_[i];  // kept where they are
      for (std::size_t i = items_.size(); i < other.items_.size(); ++i)
        items_.push_back(std::make_unique<Entry>(*other.items_[i]));
      return *this;
    }
    Entries(Entries&&) noexcept = default;
    Entries& operator=(Entries&&) noexcept = default;
    ~Entries() = default;
    Entry& operator[](std::size_t i) { return *items_[i]; }
    const Entry& operator[](std::size_t i) const { return *items_[i]; }
    std::size_t size() const { return items_.size(); }
    Entry& back() { return *items_.back(); }
    void emplace_back() { items_.push_back(std::make_unique<Entry>()); }
    template <class E, class It>
    struct Iterator {
      It it;
      E& operator*() const { return **it; }
      Iterator& operator++() {
        ++it;
        return *this;
      }
      bool operator!=(const Iterator& other) const { return it != other.it; }
    };
    using iterator = Iterator<Entry, std::vector<std::unique_ptr<Entry>>::iterator>;
    using const_iterator = Iterator<const Entry, std::vector<std::unique_ptr<Entry>>::const_iterator>;
    iterator begin() { return {items_.begin()}; }
    iterator end() { return {items_.end()}; }
    const_iterator begin() const { return {items_.begin()}; }
    const_iterator end() const { return {items_.end()}; }

   private:
    std::vector<std::unique_ptr<Entry>> items_;
  };
  Entries entries_;
  std::vector<std::uint32_t> by_key_;  // indices of entries_ in the keys' order (the order of a JSON object)
  std::vector<std::uint32_t> files_;   // indices of the file parameters (check_files)
  /// Key -> index in entries_ (looked up by a std::string_view: a literal key is not copied into a std::string).
  struct KeyHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view key) const noexcept { return std::hash<std::string_view>{}(key); }
  };
  std::unordered_map<std::string, std::uint32_t, KeyHash, std::equal_to<>> index_;
  /// The index last found for a key at a given address (a literal's: the same on every call), tried before the hash
  /// and confirmed by comparing the key (a stale or foreign guess costs one comparison, never a wrong answer).
  /// Relaxed atomics: lookups of one set from several threads are safe. A copy starts empty.
  struct LookupCache {
    static constexpr std::size_t size = 256;
    std::atomic<std::uint32_t> slots[size];
    LookupCache() noexcept { clear(); }
    LookupCache(const LookupCache&) noexcept : LookupCache() {}
    LookupCache& operator=(const LookupCache&) noexcept {
      clear();
      return *this;
    }
    void clear() noexcept {
      for (auto& s : slots) s.store(kNone, std::memory_order_relaxed);
    }
  };
  mutable LookupCache recent_;
  std::uint64_t keys_signature_ = 0;  // a hash of the keys in declaration order (reset_values)
  std::string config_path_;
  std::string group_ = "Options";
  std::uint32_t last_ = kNone;  // the parameter default_text() and unit() apply to
  std::map<std::string, std::pair<std::string, std::string>> group_conditions_;  // group -> (key, value)
  void declare(const std::string& key, Entry e, const afmkit::SourceLocation& where);
  static Entry make_entry(Value value, const std::string& help, Range range);
};

}  // namespace afmkit::io
