#include "cantilever_params.hpp"

#include "afmkit/core/units.hpp"
#include "afmkit/tapping/cantilever_limits.hpp"

namespace afmkit::cli {

namespace {
struct CantileverKeyDeclaration {
  const char* key;
  const char* unit;  // nullptr: a length (the command's length unit)
  tapping::CantileverSetting setting;  // its range, declared by the library (tapping/cantilever_limits.hpp)
  const char* range_unit;  // the unit the command line's range is in (the library's is SI)
};

CantileverKeyDeclaration cantilever_key_declaration(CantileverKey key) {
  using S = tapping::CantileverSetting;
  switch (key) {
    case CantileverKey::spring_constant: return {"spring_constant", "N/m", S::spring_constant, "N/m"};
    case CantileverKey::resonance_frequency: return {"resonance_frequency", "kHz", S::resonance_frequency, "kHz"};
    case CantileverKey::quality_factor: return {"quality_factor", "dimensionless", S::quality_factor, nullptr};
    case CantileverKey::free_amplitude: return {"free_amplitude", nullptr, S::amplitude, "nm"};
    case CantileverKey::amplitude: return {"amplitude", nullptr, S::amplitude, "nm"};
  }
  return {"", "", S::quality_factor, nullptr};  // unreachable: every key is listed above
}

/// The upper end of the key's range in the command line's unit (the tapping commands' normalised lengths L take the
/// nm bound too): wide but finite, so that the model's scales stay far inside the double range.
double cantilever_upper(const CantileverKeyDeclaration& d) {
  const double si = tapping::cantilever_limit(d.setting).upper;
  return d.range_unit != nullptr ? units::from_si(d.range_unit)(si) : si;
}
}  // namespace

void add_cantilever_param(io::ParamSet& p, CantileverKey key, CantileverDefault how, const std::string& help,
                          const char* length_unit) {
  const CantileverKeyDeclaration d = cantilever_key_declaration(key);
  using Kind = CantileverDefault::Kind;
  const io::Range range = how.kind == Kind::value      ? io::Range{0.0, cantilever_upper(d), true, false}
                          : how.kind == Kind::required ? io::Range::closed(0.0, cantilever_upper(d))
                                                       : io::Range::any();
  p.real(d.key, how.value, help, range).unit(d.unit != nullptr ? d.unit : length_unit);
  if (how.kind == Kind::required) p.default_text("required");
  if (how.kind == Kind::the_files) p.default_text("the file's");
}

}  // namespace afmkit::cli
