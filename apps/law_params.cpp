#include "law_params.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "afmkit/core/error.hpp"

namespace afmkit::cli {

void add_law_key_param(io::ParamSet& p, const impact::LawRegistry& registry, const std::string& key,
                       const LawKeyForm& form) {
  const auto& keys = registry.keys();
  const auto found = std::find_if(keys.begin(), keys.end(), [&](const impact::LawKey& k) { return k.key == key; });
  if (found == keys.end()) throw std::logic_error("add_law_key_param: '" + key + "' is no key of the law registry");
  const impact::LawKey& k = *found;
  const std::string help =
      form.help.empty() ? fmt::format("[{}] {}", fmt::join(registry.laws_using(k.key), ", "), k.help) : form.help;
  const io::Range range = form.range.value_or(io::Range{k.lower, std::min(k.upper, 1e308), k.lower_open, false});
  const std::string unit = !form.unit.empty() ? form.unit : k.unit.empty() ? "dimensionless" : k.unit;
  p.real(k.key, form.default_value.value_or(k.default_value), help, range).unit(unit);
}

void add_law_params(io::ParamSet& p, const impact::LawRegistry& registry, const std::string& default_law,
                    const std::vector<std::string>& skip, const LawKeyAliases& aliases) {
  std::vector<std::string> summaries;
  for (const auto& name : registry.names()) summaries.push_back(fmt::format("{}: {}", name, registry.find(name).summary));
  p.group("Contact law");
  p.text("law", default_law, fmt::format("tip-sample force law (docs/force-laws.md): {}", fmt::join(summaries, "; ")),
         registry.names())
      .file("force_curve", "",
            "[table] force-curve file: approach and retract force vs distance, units in the header "
            "(docs/force-laws.md)")
      .text("hysteresis", "law",
            "branch selection (docs/force-laws.md#hysteresis): law = the law's own (contact for table, velocity-sign "
            "for the others); [table] contact = the retract branch only after the tip reached the contact gap, "
            "until it rises above the release gap; velocity = by the sign of the gap rate alone (seed-1 eq. 4)",
            {"law", "contact", "velocity"})
      .flag("allow_energy_gain", false,
            "accept a law that creates energy (retract branch above the approach branch somewhere: K_b > K_a, "
            "restitution > 1, departure_modulus > effective_modulus, ...)");
  // the records list only the keys of the law in use (ParamSet::applies_when)
  std::vector<std::string> with_curve;
  for (const auto& name : registry.names())
    if (registry.find(name).needs_force_curve) with_curve.push_back(name);
  p.applies_when("force_curve", "law", with_curve);
  for (const auto& [command_key, registry_key] : aliases)
    p.applies_when(command_key, "law", registry.laws_using(registry_key));
  for (const auto& k : registry.keys()) {
    if (std::find(skip.begin(), skip.end(), k.key) != skip.end()) {  // declared by the command (same meaning)
      p.applies_when(k.key, "law", registry.laws_using(k.key));
      continue;
    }
    add_law_key_param(p, registry, k.key);
    p.applies_when(k.key, "law", registry.laws_using(k.key));
    if (!k.follows.empty()) p.follows(k.follows);  // recorded with the value it takes (params.hpp)
    if (k.only_if_given) {  // an alternative: recorded only when given, then instead of the key it replaces
      std::vector<std::string> replaced{k.replaces};
      for (const auto& [command_key, registry_key] : aliases)
        if (registry_key == k.replaces) replaced.push_back(command_key);
      p.only_if_given(std::move(replaced));
    }
  }
}

LawChoice::LawChoice(const io::ParamSet& p, const impact::LawRegistry& registry) : spec(registry.find(p.text("law"))) {
  const auto& keys = registry.keys();
  given.reserve(keys.size());
  for (const auto& k : keys) given.push_back(static_cast<char>(p.was_set(k.key)));
}

impact::ForceLaw law_from_params(const io::ParamSet& p, const impact::LawRegistry& registry,
                                 const LawKeyAliases& aliases, std::shared_ptr<const impact::ForceLawModel> object) {
  return law_from_params(p, registry, LawChoice(p, registry), aliases, std::move(object));
}

impact::ForceLaw law_from_params(const io::ParamSet& p, const impact::LawRegistry& registry, const LawChoice& choice,
                                 const LawKeyAliases& aliases, std::shared_ptr<const impact::ForceLawModel> object) {
  const impact::LawSpec& spec = choice.spec;
  const std::string& name = spec.name;
  const auto& keys = registry.keys();
  impact::LawArguments args;
  args.allow_energy_gain = p.flag("allow_energy_gain");
  args.force_curve = p.text("force_curve");
  args.hysteresis = p.text("hysteresis");
  args.model = std::move(object);
  auto reads = [&](const std::string& key) { return std::find(spec.keys.begin(), spec.keys.end(), key) != spec.keys.end(); };
  std::vector<std::string> replaced;  // keys a given alternative stands for (restitution -> departure_stiffness)
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (!keys[i].replaces.empty() && choice.given[i]) replaced.push_back(keys[i].replaces);
  const auto is_replaced = [&](const std::string& key) {
    return std::find(replaced.begin(), replaced.end(), key) != replaced.end();
  };
  for (const auto& [command_key, registry_key] : aliases) {
    // always pass an alias the law reads (its default is the command's) unless a given alternative stands for it;
    // a given alias of another law is passed too, so that the registry names it as foreign
    if ((reads(registry_key) && !is_replaced(registry_key)) || p.was_set(command_key))
      args.values[registry_key] = p.real(command_key);
  }
  // every key the law reads, with the command's value (given, or its default — a command may change defaults);
  // keys that follow another key or count only when given are passed only when given; given keys of other laws
  // are passed so that the registry names them
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const impact::LawKey& k = keys[i];
    if (args.values.count(k.key)) continue;
    const bool pass = choice.given[i] || (reads(k.key) && k.follows.empty() && !k.only_if_given && !is_replaced(k.key));
    if (pass) args.values[k.key] = p.real(k.key);
  }
  try {
    return registry.build(name, args);
  } catch (const InvalidParameter& e) {
    // name the command's key, not the registry key it stands for
    for (const auto& [command_key, registry_key] : aliases)
      if (e.parameter() == registry_key && command_key != registry_key)
        throw InvalidParameter(command_key, fmt::format("{} (given as {})", e.what(), command_key));
    throw;
  }
}

}  // namespace afmkit::cli
