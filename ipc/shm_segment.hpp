#pragma once

#include <string>

#include "ipc/shm_layout.hpp"

namespace hapticsim::shm {

/**
 * A mapping of the segment. The daemon creates it (Create), a driver opens it (Open); both
 * unmap on destruction, and the creator also unlinks the name.
 */
class MappedSegment {
 public:
  /**
   * The daemon: creates `name` afresh (a stale one left by a crash is replaced), mode 0660, group
   * `group` when not empty. @throws Error saying what failed and what to check.
   */
  static MappedSegment Create(const std::string& name, const std::string& group);
  /**
   * A driver: opens an existing segment and checks its header (magic, layout version, sizes).
   * @throws Error saying which check failed.
   */
  static MappedSegment Open(const std::string& name);

  MappedSegment(MappedSegment&& other) noexcept;
  MappedSegment& operator=(MappedSegment&&) = delete;
  ~MappedSegment();

  ShmSegment& segment() { return *segment_; }
  const ShmSegment& segment() const { return *segment_; }
  const std::string& name() const { return name_; }

 private:
  MappedSegment(std::string name, ShmSegment* segment, bool owner)
      : name_(std::move(name)), segment_(segment), owner_(owner) {}
  std::string name_;
  ShmSegment* segment_ = nullptr;
  bool owner_ = false;
};

}  // namespace hapticsim::shm
