#include "cantilever_params.hpp"

namespace afmkit::cli {

namespace {
struct CantileverKeyDeclaration {
  const char* key;
  const char* unit;  // nullptr: a length (the command's length unit)
  double upper;      // a value given is in (0, upper]: wide but finite, so that the model's scales stay far inside
                     // the double range (real cantilevers lie decades inside)
};

CantileverKeyDeclaration cantilever_key_declaration(CantileverKey key) {
  switch (key) {
    case CantileverKey::spring_constant: return {"spring_constant", "N/m", 1e6};
    case CantileverKey::resonance_frequency: return {"resonance_frequency", "kHz", 1e7};
    case CantileverKey::quality_factor: return {"quality_factor", "dimensionless", 1e9};
    case CantileverKey::free_amplitude: return {"free_amplitude", nullptr, 1e6};
    case CantileverKey::amplitude: return {"amplitude", nullptr, 1e6};
  }
  return {"", "", 0.0};  // unreachable: every key is listed above
}
}  // namespace

void add_cantilever_param(io::ParamSet& p, CantileverKey key, CantileverDefault how, const std::string& help,
                          const char* length_unit) {
  const CantileverKeyDeclaration d = cantilever_key_declaration(key);
  using Kind = CantileverDefault::Kind;
  const io::Range range = how.kind == Kind::value      ? io::Range{0.0, d.upper, true, false}
                          : how.kind == Kind::required ? io::Range::closed(0.0, d.upper)
                                                       : io::Range::any();
  p.real(d.key, how.value, help, range).unit(d.unit != nullptr ? d.unit : length_unit);
  if (how.kind == Kind::required) p.default_text("required");
  if (how.kind == Kind::the_files) p.default_text("the file's");
}

}  // namespace afmkit::cli
