#pragma once
// The force-law parameters of every command, declared and read in one place from impact::LawRegistry
// (docs/force-laws.md): `law`, `force_curve`, `allow_energy_gain` and every law parameter with its unit.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "afmkit/impact/law_registry.hpp"
#include "afmkit/io/params.hpp"

namespace afmkit::cli {

/// Keys that a command declares itself (other unit or default than the registry's) and maps onto registry keys:
/// command key -> registry key. The command key's value (given or default) is passed whenever the chosen law
/// reads the registry key.
using LawKeyAliases = std::map<std::string, std::string>;

/// How a command that takes a registry key outside add_law_params (in its own unit system or role) differs from the
/// registry's declaration of it; unset fields are the registry's.
struct LawKeyForm {
  std::string help;                  // empty: "[laws] " + the registry's help
  std::optional<double> default_value;
  std::optional<io::Range> range;    // unset: the registry's range
  std::string unit;                  // empty: the registry's unit
};
/// Declares the registry key `key` on `p` (the one declaration of every law key, also add_law_params'), in `form`.
void add_law_key_param(io::ParamSet& p, const impact::LawRegistry& registry, const std::string& key,
                       const LawKeyForm& form = {});

/// Declares `law` (default `default_law`), `force_curve`, `allow_energy_gain` and every registry key not in
/// `skip` (keys the command declares itself, in its own form: add_law_key_param). Every law key, alias and skipped
/// key, and `force_curve`, applies only to the laws that read it (ParamSet::applies_when): the records list the
/// keys of the law in use.
/// `aliases`: the command keys that stand for registry keys (law_from_params), so that an alternative given
/// (restitution) leaves the command key it replaces out of the records too.
void add_law_params(io::ParamSet& p, const impact::LawRegistry& registry, const std::string& default_law,
                    const std::vector<std::string>& skip = {}, const LawKeyAliases& aliases = {});
/// What a run asks of the registry, read from its parameters once and shared by the checks of the run (a command's
/// own, law_from_params'): the law chosen (`law`) and which registry keys were given.
struct LawChoice {
  /// `p` declares `law` and every registry key (add_law_params); InvalidParameter("law") for an unknown law.
  LawChoice(const io::ParamSet& p, const impact::LawRegistry& registry);
  const impact::LawSpec& spec;
  std::vector<char> given;  ///< per key of registry.keys(), in order: given (ParamSet::was_set)
};

/// The law the parameters describe (InvalidParameter naming the key for a key of another law, a value out of
/// range or an unknown law). `aliases`: command keys whose values stand for registry keys.
/// `object`: the law object of law = python (the caller's, law_object_of; null on the command line).
impact::ForceLaw law_from_params(const io::ParamSet& p, const impact::LawRegistry& registry,
                                 const LawKeyAliases& aliases = {},
                                 std::shared_ptr<const impact::ForceLawModel> object = nullptr);
/// The same for a choice already read (LawChoice(p, registry)).
impact::ForceLaw law_from_params(const io::ParamSet& p, const impact::LawRegistry& registry, const LawChoice& choice,
                                 const LawKeyAliases& aliases = {},
                                 std::shared_ptr<const impact::ForceLawModel> object = nullptr);

}  // namespace afmkit::cli
