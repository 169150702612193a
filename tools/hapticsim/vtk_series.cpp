#include "tools/hapticsim/vtk_series.hpp"

#include <cstdio>
#include <fstream>
#include <system_error>

#include "core/error.hpp"
#include "core/fem/lattice_stress.hpp"

namespace hapticsim::cli {
namespace fs = std::filesystem;

VtkSeries::VtkSeries(const fs::path& dir, const std::string& name, const Scene& scene,
                     std::vector<RegionIndex> region_per_cell)
    : dir_(dir), name_(name), scene_(scene), region_per_cell_(std::move(region_per_cell)) {
  std::error_code error;
  fs::create_directories(dir_ / name_, error);
  HAPTICSIM_THROW_UNLESS(
      !error, "cannot make the folder " + (dir_ / name_).string() + ": " + error.message());
}

void VtkSeries::Write(double t_s, const ObjectState& state) {
  const int n = state.lattice_nodes[0];  // the cube: --vtk is refused for other objects
  const int cells = (n - 1) * (n - 1) * (n - 1);
  HAPTICSIM_THROW_UNLESS(static_cast<int>(region_per_cell_.size()) == cells,
                         "internal: the regions are not the lattice's cells");
  const double h = scene_.mesh.edge_m / (n - 1);
  char file[32];
  std::snprintf(file, sizeof file, "frame_%05d.vtu", frames());
  const std::string relative = name_ + "/" + file;
  std::ofstream out(dir_ / relative);
  HAPTICSIM_THROW_UNLESS(out.good(), "cannot write " + (dir_ / relative).string());
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n<UnstructuredGrid>\n"
      << "<Piece NumberOfPoints=\"" << n * n * n << "\" NumberOfCells=\"" << cells << "\">\n"
      << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  // Points in ObjectState's order: point (ix, iy, iz) is number (ix·n + iy)·n + iz.
  for (int ix = 0; ix < n; ++ix) {
    for (int iy = 0; iy < n; ++iy) {
      for (int iz = 0; iz < n; ++iz) out << ix * h << ' ' << iy * h << ' ' << iz * h << '\n';
    }
  }
  out << "</DataArray></Points>\n<Cells>\n"
      << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  auto point = [n](int ix, int iy, int iz) { return (ix * n + iy) * n + iz; };
  for (int ix = 0; ix + 1 < n; ++ix) {
    for (int iy = 0; iy + 1 < n; ++iy) {
      for (int iz = 0; iz + 1 < n; ++iz) {
        // VTK_HEXAHEDRON: the bottom face counter-clockwise, then the top face above it.
        out << point(ix, iy, iz) << ' ' << point(ix + 1, iy, iz) << ' ' << point(ix + 1, iy + 1, iz)
            << ' ' << point(ix, iy + 1, iz) << ' ' << point(ix, iy, iz + 1) << ' '
            << point(ix + 1, iy, iz + 1) << ' ' << point(ix + 1, iy + 1, iz + 1) << ' '
            << point(ix, iy + 1, iz + 1) << '\n';
      }
    }
  }
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (int c = 1; c <= cells; ++c) out << 8 * c << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int c = 0; c < cells; ++c) out << "12\n";
  out << "</DataArray>\n</Cells>\n<PointData Vectors=\"displacement_m\">\n"
      << "<DataArray type=\"Float64\" Name=\"displacement_m\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (size_t i = 0; i < state.displacement_m.size(); i += 3) {
    out << state.displacement_m[i] << ' ' << state.displacement_m[i + 1] << ' '
        << state.displacement_m[i + 2] << '\n';
  }
  out << "</DataArray>\n</PointData>\n<CellData Scalars=\"von_mises_pa\">\n"
      << "<DataArray type=\"Float64\" Name=\"von_mises_pa\" format=\"ascii\">\n";
  for (double s : VonMisesPerCell(state, h, scene_.material)) out << s << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n";
  for (RegionIndex r : region_per_cell_) out << r << '\n';
  out << "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  HAPTICSIM_THROW_UNLESS(out.good(),
                         "writing " + (dir_ / relative).string() + " failed (disk full?)");
  written_.emplace_back(t_s, relative);
}

void VtkSeries::Finish() {
  std::ofstream out(collection());
  HAPTICSIM_THROW_UNLESS(out.good(), "cannot write " + collection().string());
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n<Collection>\n";
  for (const auto& [t, file] : written_) {
    out << "<DataSet timestep=\"" << t << "\" part=\"0\" file=\"" << file << "\"/>\n";
  }
  out << "</Collection>\n</VTKFile>\n";
  HAPTICSIM_THROW_UNLESS(out.good(), "writing " + collection().string() + " failed (disk full?)");
}

}  // namespace hapticsim::cli
