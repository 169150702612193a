#pragma once

#include <cstddef>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "core/errormap/error_map.hpp"
#include "core/errormap/sweep_grid.hpp"

namespace hapticsim {

struct SweepOptions;

/**
 * What identifies one sweep, for its journal: the scene, the model, the code version, the grid,
 * the shard and the savings used, and every sample's point (FNV-1a, as hex). A journal of another
 * sweep is refused on --resume.
 */
std::string SweepFingerprint(const ErrorMap& map, const SweepGrid& grid,
                             const SweepOptions& options);

/**
 * The tasks a journal of the sweep `fingerprint` holds as completed, their samples written into
 * `map`; none when the file does not exist. A torn last line (a crash mid-write) is ignored.
 * @throws Error when the file belongs to another sweep or is not a journal (what to do is said).
 */
std::vector<bool> ReadSweepJournal(const std::string& path, const std::string& fingerprint,
                                   std::size_t num_tasks, ErrorMap* map);

/**
 * The journal a sweep appends each completed task to, a JSON line each, flushed at once: what
 * --resume skips after an interruption or a crash. Not thread-safe: the caller serialises Append.
 */
class SweepJournal {
 public:
  /** No journal (`path` empty), or `path` for the sweep `fingerprint`: appended to when
   *  `resume` and it exists, else written anew with its header. @throws Error when it cannot be
   *  written. */
  SweepJournal(const std::string& path, const std::string& fingerprint, bool resume);
  /** Task `task` completed with these samples (their indices in the map). */
  void Append(std::size_t task, const std::vector<std::pair<std::size_t, MapSample>>& samples);

 private:
  std::ofstream out_;
};

}  // namespace hapticsim
