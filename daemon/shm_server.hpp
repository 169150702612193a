#pragma once

#include <spdlog/spdlog.h>

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "daemon/haptic_loop.hpp"
#include "daemon/input_counters.hpp"
#include "daemon/input_intake.hpp"
#include "ipc/service_socket.hpp"
#include "ipc/shm_segment.hpp"

namespace hapticsim {

/**
 * The shared-memory side of the I/O thread. Listens on the service socket (ipc/service_socket.hpp)
 * and gives each driver it admits a new sealed segment of its own: a driver that leaves, or is
 * replaced by the next one, keeps a mapping nobody reads or writes any more, so no session sees
 * another's. Takes each new device input from the session's segment (checked like LCM input), and
 * writes every force back. Only the I/O thread calls PollInput, Publish and
 * PublishPendingDeformation; the deformation thread hands its frames over with OfferDeformation.
 */
class ShmServer {
 public:
  /** @throws Error when the socket cannot be made (the message says what to check). */
  ShmServer(const std::string& socket_path, const std::string& group, double workspace_margin_m,
            double max_speed_m_per_s, double max_log_lines_per_s, HapticLoop& loop,
            InputCounters& counters, bool owns_input);

  /** Answers drivers that connected, notices one that left, reads the session's inputs, and
   *  writes a deformed surface offered since (PublishPendingDeformation). */
  void PollInput();
  void Publish(const ForceRecord& record);
  /**
   * The deformation thread: keeps `frame` (made at `utime_us`, number `number`) for the I/O thread
   * to write into the session's segment. Takes a lock the I/O thread only ever tries.
   */
  void OfferDeformation(const HapticLoop::SurfaceFrame& frame, std::int64_t utime_us,
                        std::int64_t number);
  /** The I/O thread: writes a frame offered since the last call, unless the deformation thread
   *  holds it right now (then at the next call). A new session gets the newest at once. */
  void PublishPendingDeformation();
  const std::string& socket_path() const { return listener_.path(); }

 private:
  void Admit(shm::Connection connection);
  void EndSessionIfGone();
  /** At most max_log_lines_per_s lines: a connect flood must not flood the journal. */
  template <typename... Args>
  void Log(spdlog::level::level_enum level, const char* format, const Args&... args);

  shm::ServiceListener listener_;
  InputIntake intake_;
  std::optional<shm::MappedSegment> mapping_;  // the session's, while there is one
  shm::UniqueFd session_;                      // the driver's connection while it drives
  shm::PeerIdentity session_peer_;             // and who it is
  shm::ShmInputReader inputs_;
  const std::uint32_t surface_nodes_;  // every frame's, for the segment's size
  // The newest frame offered, under deformation_mutex_, and whether the session has it yet.
  std::mutex deformation_mutex_;
  shm::ShmDeformationFrame deformation_meta_;
  std::vector<std::int32_t> deformation_ids_;
  std::vector<double> deformation_u_;
  bool deformation_fresh_ = false;
  // The I/O thread's own: frames written into this session's segment, and whether a new session
  // still needs the newest frame.
  std::int64_t deformation_writes_ = 0;
  bool deformation_for_new_session_ = false;
  InputCounters& counters_;  // sessions started and connections refused are counted there
  double min_log_gap_ns_;
  std::int64_t last_log_ns_ = 0, unlogged_ = 0;
};

}  // namespace hapticsim
