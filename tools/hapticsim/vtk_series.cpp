#include "tools/hapticsim/vtk_series.hpp"

#include <cstdio>
#include <fstream>
#include <system_error>

#include "core/error.hpp"
#include "core/fem/lattice_stress.hpp"

namespace hapticsim::cli {
namespace fs = std::filesystem;

namespace {

std::vector<VtkSeries::Cell> OccupiedCells(const VtkObject& object) {
  const auto [nx, ny, nz] = object.lattice_nodes;
  std::vector<VtkSeries::Cell> cells;
  size_t cell = 0;
  for (int ix = 0; ix + 1 < nx; ++ix) {
    for (int iy = 0; iy + 1 < ny; ++iy) {
      for (int iz = 0; iz + 1 < nz; ++iz, ++cell) {
        if (object.cell_material[cell] >= 0) cells.push_back({cell, {ix, iy, iz}});
      }
    }
  }
  return cells;
}

// Points in ObjectState's order: point (ix, iy, iz) is number (ix·ny + iy)·nz + iz.
void WritePoints(std::ostream& out, const VtkObject& object) {
  const auto [nx, ny, nz] = object.lattice_nodes;
  const double h = object.spacing_m;
  out << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int ix = 0; ix < nx; ++ix) {
    for (int iy = 0; iy < ny; ++iy) {
      for (int iz = 0; iz < nz; ++iz) out << ix * h << ' ' << iy * h << ' ' << iz * h << '\n';
    }
  }
  out << "</DataArray></Points>\n";
}

void WriteCells(std::ostream& out, const VtkObject& object,
                const std::vector<VtkSeries::Cell>& cells) {
  const int ny = object.lattice_nodes[1], nz = object.lattice_nodes[2];
  auto point = [ny, nz](int ix, int iy, int iz) {
    return (static_cast<long>(ix) * ny + iy) * nz + iz;
  };
  out << "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const VtkSeries::Cell& cell : cells) {
    const auto [ix, iy, iz] = cell.corner;
    // VTK_HEXAHEDRON: the bottom face counter-clockwise, then the top face above it.
    out << point(ix, iy, iz) << ' ' << point(ix + 1, iy, iz) << ' ' << point(ix + 1, iy + 1, iz)
        << ' ' << point(ix, iy + 1, iz) << ' ' << point(ix, iy, iz + 1) << ' '
        << point(ix + 1, iy, iz + 1) << ' ' << point(ix + 1, iy + 1, iz + 1) << ' '
        << point(ix, iy + 1, iz + 1) << '\n';
  }
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t c = 1; c <= cells.size(); ++c) out << 8 * c << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (size_t c = 0; c < cells.size(); ++c) out << "12\n";
  out << "</DataArray>\n</Cells>\n";
}

}  // namespace

VtkObject VtkObjectOf(const SceneObject& object) {
  const HexGrid& grid = object.grid;
  VtkObject out{{grid.nx(), grid.ny(), grid.nz()}, grid.spacing(), object.field.materials(), {}};
  for (int ix = 0; ix + 1 < grid.nx(); ++ix) {
    for (int iy = 0; iy + 1 < grid.ny(); ++iy) {
      for (int iz = 0; iz + 1 < grid.nz(); ++iz) {
        out.cell_material.push_back(object.field.material_of(object.field.Element(ix, iy, iz)));
      }
    }
  }
  return out;
}

VtkSeries::VtkSeries(const fs::path& dir, const std::string& name, VtkObject object,
                     std::vector<RegionIndex> region_per_cell)
    : dir_(dir),
      name_(name),
      object_(std::move(object)),
      cells_(OccupiedCells(object_)),
      region_per_cell_(std::move(region_per_cell)) {
  HAPTICSIM_THROW_UNLESS(region_per_cell_.size() == object_.cell_material.size(),
                         "internal: the regions are not the lattice's cells");
  std::error_code error;
  fs::create_directories(dir_ / name_, error);
  HAPTICSIM_THROW_UNLESS(
      !error, "cannot make the folder " + (dir_ / name_).string() + ": " + error.message());
}

void VtkSeries::SetRegions(std::vector<RegionIndex> region_per_cell) {
  HAPTICSIM_THROW_UNLESS(region_per_cell.size() == object_.cell_material.size(),
                         "internal: the regions are not the lattice's cells");
  region_per_cell_ = std::move(region_per_cell);
}

void VtkSeries::Write(double t_s, const ObjectState& state) {
  HAPTICSIM_THROW_UNLESS(state.lattice_nodes == object_.lattice_nodes,
                         "internal: a frame of another lattice");
  char file[32];
  std::snprintf(file, sizeof file, "frame_%05d.vtu", frames());
  const std::string relative = name_ + "/" + file;
  std::ofstream out(dir_ / relative);
  HAPTICSIM_THROW_UNLESS(out.good(), "cannot write " + (dir_ / relative).string());
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n<UnstructuredGrid>\n"
      << "<Piece NumberOfPoints=\"" << state.num_points() << "\" NumberOfCells=\"" << cells_.size()
      << "\">\n";
  WritePoints(out, object_);
  WriteCells(out, object_, cells_);
  out << "<PointData Vectors=\"displacement_m\">\n"
      << "<DataArray type=\"Float64\" Name=\"displacement_m\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (size_t i = 0; i < state.displacement_m.size(); i += 3) {
    out << state.displacement_m[i] << ' ' << state.displacement_m[i + 1] << ' '
        << state.displacement_m[i + 2] << '\n';
  }
  out << "</DataArray>\n</PointData>\n<CellData Scalars=\"von_mises_pa\">\n"
      << "<DataArray type=\"Float64\" Name=\"von_mises_pa\" format=\"ascii\">\n";
  const std::vector<double> stress =
      VonMisesPerCell(state, object_.spacing_m, object_.materials, object_.cell_material);
  for (const VtkSeries::Cell& cell : cells_) out << stress[cell.lattice_cell] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n";
  for (const VtkSeries::Cell& cell : cells_) out << region_per_cell_[cell.lattice_cell] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"material\" format=\"ascii\">\n";
  for (const VtkSeries::Cell& cell : cells_) {
    out << object_.cell_material[cell.lattice_cell] << '\n';
  }
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
