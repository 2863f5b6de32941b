#include "afmkit/tapping/events.hpp"

namespace afmkit::tapping {

const char* contact_branch_name(ContactBranch branch) {
  switch (branch) {
    case ContactBranch::approach: return "approach";
    case ContactBranch::departure: return "departure";
    case ContactBranch::sticking: return "sticking";
  }
  return "?";
}

const char* guard_kind_name(GuardKind kind) {
  switch (kind) {
    case GuardKind::gap: return "gap";
    case GuardKind::velocity: return "velocity";
    case GuardKind::release_departure: return "release_departure";
    case GuardKind::release_approach: return "release_approach";
  }
  return "?";
}

}  // namespace afmkit::tapping
