#pragma once

#include <stdexcept>
#include <string>

namespace hapticsim {

/**
 * The one exception type of hapticsim. Thrown at boundaries (scene files, command-line values,
 * model construction) with a message that says what was wrong and what is allowed; caught once
 * in each program's main. Never thrown from a time step: those return a status instead.
 */
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hapticsim

/// Throws hapticsim::Error with `message` unless `condition` holds. For caller errors.
#define HAPTICSIM_THROW_UNLESS(condition, message)       \
  do {                                                   \
    if (!(condition)) throw ::hapticsim::Error(message); \
  } while (false)
