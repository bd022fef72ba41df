#include <clearway/narrowphase/status.h>

namespace clearway {

const char* statusName(Status s) noexcept {
  switch (s) {
    case Status::Converged: return "converged";
    case Status::RepeatedSupport: return "repeated_support";
    case Status::NoProgress: return "no_progress";
    case Status::Touching: return "touching";
    case Status::Overlapping: return "overlapping";
    case Status::Separated: return "separated";
    case Status::NotConverged: return "not_converged";
    case Status::InvalidInput: return "invalid_input";
  }
  return "unknown";
}

}  // namespace clearway
