#pragma once

#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/input_intake.hpp"
#include "ipc/shm_segment.hpp"

namespace hapticsim {

/**
 * The shared-memory side of the I/O thread: creates the segment (ipc/shm_layout.hpp), takes each
 * new device input from it (checked like LCM input), and writes every force back. Only the I/O
 * thread calls PollInput and Publish.
 */
class ShmServer {
 public:
  /** @throws Error when the segment cannot be created (the message says what to check). */
  ShmServer(const std::string& name, const std::string& group, const MeshSettings& mesh,
            double workspace_margin_m, double max_speed_m_per_s, HapticLoop& loop,
            InputCounters& counters, bool owns_input);

  void PollInput();
  void Publish(const ForceRecord& record);
  const std::string& name() const { return mapping_.name(); }

 private:
  shm::MappedSegment mapping_;
  InputIntake intake_;
  shm::ShmInputReader inputs_;
};

}  // namespace hapticsim
