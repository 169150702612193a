#pragma once

#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace hapticsim::testing {

/**
 * A path for hapticsimd's service socket (shm.socket) in a new directory only this user can
 * write (mode 0700), as a driver requires of the directory it trusts a socket in.
 */
inline std::string PrivateSocketPath() {
  char directory[] = "/tmp/hapticsim-test-XXXXXX";
  if (!mkdtemp(directory)) {
    throw std::runtime_error(std::string("mkdtemp: ") + std::strerror(errno));
  }
  return std::string(directory) + "/hapticsimd.sock";
}

}  // namespace hapticsim::testing
