#pragma once

#include <string>
#include <vector>

#include "core/errormap/error_lookup.hpp"
#include "core/errormap/error_map.hpp"

namespace hapticsim {

/*
 * The error map file (".hsmap"), little-endian:
 *
 *   magic "HSIMMAP\x1a" · u32 format version · u32 section count · u64 directory checksum
 *   directory: per section { char name[32] · u64 offset · u64 size · u64 checksum }
 *   sections:
 *     "meta"              JSON: provenance, axes with values and units, sample count
 *     "lookup.l2_percent", "lookup.max_magnitude_percent", "lookup.max_direction_deg"
 *                         f64 per sample: one lookup table each
 *     "status"            u8 status + i8 region per sample
 *     "details"           f64 per sample: the point (12), reference peak, spectral radius,
 *                         cost per region (4)
 *
 * Every section has its own checksum, so the daemon reads and checks only what it looks up.
 */
/**
 * File format version written by SaveErrorMap and the only one LoadErrorMap reads.
 * 2: the contact node's three axes appended (version 1 maps have nine axes).
 * 3: the material contrast appended (version 2 maps have twelve axes).
 */
inline constexpr std::uint32_t kErrorMapFormatVersion = 3;

/** Writes the map atomically (a temporary file renamed over `path`). @throws Error on I/O. */
void SaveErrorMap(const ErrorMap& map, const std::string& path);

/** Which parts of a map file to read: the daemon needs only the lookup table. */
enum class MapLoadParts { kLookupOnly, kEverything };

/**
 * Reads and checks a map file.
 * @throws Error saying which: not a map file, wrong format version, truncated, corrupted
 *         (checksum), or inconsistent sizes.
 */
ErrorMap LoadErrorMap(const std::string& path, MapLoadParts parts = MapLoadParts::kEverything);

/**
 * What the daemon loads: one lookup table and the status of every sample, nothing else.
 * @throws Error as LoadErrorMap, or for a scattered map.
 */
ErrorLookup LoadErrorLookup(const std::string& path, ErrorField field);

/**
 * Joins shards of one sweep: same axes, base scene, model and code; each sample computed in at
 * most one of them (a sample computed in two must agree).
 * @throws Error naming the first shard that does not fit.
 */
ErrorMap MergeErrorMaps(const std::vector<ErrorMap>& shards);

}  // namespace hapticsim
