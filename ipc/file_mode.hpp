#pragma once

#include <sys/types.h>

#include <cstdio>
#include <string>

namespace hapticsim::shm {

/** A file's permission bits as chmod takes them ("0660"), for messages that say what to fix. */
inline std::string OctalMode(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

}  // namespace hapticsim::shm
