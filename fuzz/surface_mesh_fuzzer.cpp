// Fuzz target: a surface mesh file (STL or OBJ bytes → ReadSurfaceMesh → CheckClosed →
// VoxeliseClosedSurface). Anything may be refused with an Error; nothing may crash, hang or
// allocate without bound.
//
// The reader takes a path and chooses the format by extension, so the input is written to a
// per-process file in /dev/shm: the first byte chooses the extension (even: .stl, odd: .obj),
// the rest is the file. An accepted mesh is voxelised at a spacing of its bounding box's
// diagonal / 16, so the lattice stays within 16 × 16 × 16 voxels; a flat or infinite box makes
// that spacing 0 or infinite, which the voxeliser itself must refuse.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/error.hpp"
#include "core/geometry/surface_mesh.hpp"
#include "core/geometry/surface_mesh_reader.hpp"
#include "core/geometry/voxelise.hpp"

namespace {

double BoundingBoxDiagonal(const hapticsim::TriangleMesh& mesh) {
  std::array<double, 3> low = mesh.vertices.front(), high = mesh.vertices.front();
  for (const auto& vertex : mesh.vertices) {
    for (int axis = 0; axis < 3; ++axis) {
      low[axis] = std::min(low[axis], vertex[axis]);
      high[axis] = std::max(high[axis], vertex[axis]);
    }
  }
  return std::hypot(high[0] - low[0], high[1] - low[1], high[2] - low[2]);
}

bool WriteFile(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return false;
  const bool written = size == 0 || std::fwrite(data, 1, size, file) == size;
  return std::fclose(file) == 0 && written;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string path = "/dev/shm/hapticsim-surface-mesh-fuzz-" + std::to_string(::getpid()) +
                           (data[0] % 2 == 0 ? ".stl" : ".obj");
  if (!WriteFile(path, data + 1, size - 1)) __builtin_trap();  // /dev/shm must be writable
  try {
    const hapticsim::TriangleMesh mesh = hapticsim::ReadSurfaceMesh(path);
    if (mesh.vertices.empty() || mesh.triangles.empty()) __builtin_trap();  // promised refused
    hapticsim::CheckClosed(mesh);
    const hapticsim::LabelVolume volume =
        hapticsim::VoxeliseClosedSurface(mesh, BoundingBoxDiagonal(mesh) / 16);
    hapticsim::ValidateLabelVolume(volume);
    for (int axis = 0; axis < 3; ++axis) {
      if (volume.voxels[axis] > 17) __builtin_trap();  // diagonal / 16 bounds every axis
    }
  } catch (const hapticsim::Error&) {
  }
  std::remove(path.c_str());
  return 0;
}
