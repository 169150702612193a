#pragma once

#include <cstdint>

#include "daemon/daemon_config.hpp"
#include "daemon/input_counters.hpp"

namespace hapticsim {

/**
 * Device input refused, said in the log: input rejected by its checks (the last accepted input
 * stays in use), and input on the transport that does not own the input (device.input) — at most
 * log.max_lines_per_s lines a second; the counts are in every status message. Supervisor thread.
 */
class InputRejectionLog {
 public:
  /** `config`: the running one (its log.max_lines_per_s may change on SIGHUP). */
  InputRejectionLog(InputCounters& counters, const DaemonConfig& config);
  /** Says what was refused since the last line, when a line is due. */
  void Read(std::int64_t now_ns);

 private:
  InputCounters& counters_;
  const DaemonConfig& config_;
  const char* owner_name_;  // the transport that owns the input
  const char* other_name_;
  std::int64_t last_line_ns_ = 0;
  std::int64_t wrong_transport_seen_ = 0;
};

}  // namespace hapticsim
