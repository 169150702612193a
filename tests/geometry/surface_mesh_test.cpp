#include "core/geometry/surface_mesh.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "core/geometry/surface_mesh_reader.hpp"
#include "core/geometry/voxelise.hpp"
#include "tests/geometry/mesh_shapes.hpp"

namespace hapticsim {
namespace {

using test::Box;

/// The Error message `action` throws, or "" (a failure) if it throws none.
template <typename Action>
std::string ErrorOf(Action action) {
  try {
    action();
  } catch (const Error& error) {
    return error.what();
  }
  ADD_FAILURE() << "no Error thrown";
  return "";
}

#define EXPECT_MENTIONS(message_expression, phrase)                                          \
  do {                                                                                       \
    const std::string expect_mentions_text = (message_expression);                           \
    EXPECT_NE(expect_mentions_text.find(phrase), std::string::npos) << expect_mentions_text; \
  } while (false)

TEST(CheckClosed, ATetrahedronAndACubeAreClosed) {
  EXPECT_NO_THROW(CheckClosed(test::Tetrahedron()));
  EXPECT_NO_THROW(CheckClosed(Box({0, 0, 0}, {1, 2, 3})));
  EXPECT_NO_THROW(CheckClosed(test::Flipped(Box({0, 0, 0}, {1, 2, 3}))));
}

TEST(CheckClosed, EdgesMatchByPositionNotByIndex) {
  // Every triangle with its own three corners, as an STL stores them.
  const TriangleMesh box = Box({0, 0, 0}, {1, 1, 1});
  TriangleMesh soup;
  for (const auto& t : box.triangles) {
    const int first = static_cast<int>(soup.vertices.size());
    for (int corner : t) soup.vertices.push_back(box.vertices[corner]);
    soup.triangles.push_back({first, first + 1, first + 2});
  }
  EXPECT_NO_THROW(CheckClosed(soup));
}

TEST(CheckClosed, ACubeMissingOneTriangleHasThreeOpenEdgesAndSaysWhere) {
  TriangleMesh box = Box({0, 0, 0}, {0.01, 0.02, 0.03});
  box.triangles.erase(box.triangles.begin() + 2);  // {4, 5, 7}: half the top face
  const std::string message = ErrorOf([&] { CheckClosed(box); });
  EXPECT_MENTIONS(message, "not closed");
  EXPECT_MENTIONS(message, "3 edges are open");
  EXPECT_MENTIONS(message, "0 are shared by more than two");
  // The first open edge in the mesh's order is on the other top triangle {4, 7, 6}: 4 → 7.
  EXPECT_MENTIONS(message, "from (0, 0, 0.03) m to (0.01, 0.02, 0.03) m");
}

TEST(CheckClosed, AFinOfThreeTrianglesOnOneEdgeIsRefused) {
  TriangleMesh box = Box({0, 0, 0}, {1, 1, 1});
  // A third triangle on the bottom front edge (0 → 1), sticking out below.
  box.vertices.push_back({0.5, 0, -1});
  box.triangles.push_back({0, 1, 8});
  const std::string message = ErrorOf([&] { CheckClosed(box); });
  EXPECT_MENTIONS(message, "1 are shared by more than two");
  EXPECT_MENTIONS(message, "2 edges are open");  // the fin's own two free edges
}

TEST(CheckClosed, ANonFiniteVertexIsRefused) {
  TriangleMesh box = Box({0, 0, 0}, {1, 1, 1});
  box.vertices[5][1] = std::nan("");
  EXPECT_MENTIONS(ErrorOf([&] { CheckClosed(box); }),
                  "vertex 5 has a coordinate that is not finite");
}

TEST(CheckClosed, AnIndexOutOfRangeIsRefused) {
  TriangleMesh box = Box({0, 0, 0}, {1, 1, 1});
  box.triangles[3][1] = 8;
  EXPECT_MENTIONS(ErrorOf([&] { CheckClosed(box); }), "refers to vertex 8, but the mesh has 8");
  box.triangles[3][1] = -1;
  EXPECT_MENTIONS(ErrorOf([&] { CheckClosed(box); }), "refers to vertex -1");
}

TEST(CheckClosed, ATriangleWithTwoCornersAtOnePositionIsRefused) {
  TriangleMesh box = Box({0, 0, 0}, {1, 1, 1});
  box.vertices.push_back(box.vertices[7]);  // a copy of vertex 7 at its position
  box.triangles.push_back({7, 8, 0});
  EXPECT_MENTIONS(ErrorOf([&] { CheckClosed(box); }), "two corners at the same position (1, 1, 1)");
  EXPECT_MENTIONS(ErrorOf([&] { CheckClosed(TriangleMesh{}); }), "no triangles");
}

// ---------------------------------------------------------------------------------------------
// ReadSurfaceMesh: files written here by hand, not by Assimp.

class ReadSurfaceMeshTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("hapticsim_surface_mesh_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& bytes) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  std::filesystem::path dir_;
};

/// The box [0, 10] × [0, 20] × [0, 30] (units) as 12 outward triangles, corner by corner.
std::vector<std::array<test::Vec3, 3>> BoxFacets() {
  const TriangleMesh box = Box({0, 0, 0}, {10, 20, 30});
  std::vector<std::array<test::Vec3, 3>> facets;
  for (const auto& t : box.triangles) {
    facets.push_back({box.vertices[t[0]], box.vertices[t[1]], box.vertices[t[2]]});
  }
  return facets;
}

std::string AsciiStl(const std::vector<std::array<test::Vec3, 3>>& facets) {
  std::ostringstream out;
  out << "solid box\n";
  for (const auto& facet : facets) {
    out << "  facet normal 0 0 0\n    outer loop\n";
    for (const auto& v : facet)
      out << "      vertex " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    out << "    endloop\n  endfacet\n";
  }
  out << "endsolid box\n";
  return out.str();
}

/// 80-byte header, triangle count, 50 bytes per triangle (normal, 3 corners, attribute).
std::string BinaryStl(const std::vector<std::array<test::Vec3, 3>>& facets,
                      std::uint32_t declared_triangles) {
  std::string bytes(80, ' ');
  bytes.replace(0, 15, "binary box test");
  bytes.append(reinterpret_cast<const char*>(&declared_triangles), 4);
  for (const auto& facet : facets) {
    float record[12] = {};
    for (int k = 0; k < 3; ++k) {
      for (int axis = 0; axis < 3; ++axis)
        record[3 + 3 * k + axis] = static_cast<float>(facet[k][axis]);
    }
    bytes.append(reinterpret_cast<const char*>(record), sizeof record);
    bytes.append(2, '\0');
  }
  return bytes;
}

std::string BoxObj(int extra_index = 0) {
  const TriangleMesh box = Box({0, 0, 0}, {10, 20, 30});
  std::ostringstream out;
  out << "# box\no box\n";
  for (const auto& v : box.vertices) out << "v " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
  for (const auto& t : box.triangles) {
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << (extra_index ? extra_index : t[2] + 1)
        << '\n';
  }
  return out.str();
}

void ExpectMillimetreBox(const TriangleMesh& mesh) {
  EXPECT_EQ(mesh.vertices.size(), 8u);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  test::Vec3 high = {0, 0, 0};
  for (const auto& v : mesh.vertices) {
    for (int axis = 0; axis < 3; ++axis) high[axis] = std::max(high[axis], v[axis]);
  }
  EXPECT_DOUBLE_EQ(high[0], 0.010);
  EXPECT_DOUBLE_EQ(high[1], 0.020);
  EXPECT_DOUBLE_EQ(high[2], 0.030);
  EXPECT_NO_THROW(CheckClosed(mesh));
  EXPECT_NEAR(test::EnclosedVolume(mesh), 0.010 * 0.020 * 0.030, 1e-12);
}

TEST_F(ReadSurfaceMeshTest, ReadsABoxFromAsciiStlBinaryStlAndObjInMillimetres) {
  ExpectMillimetreBox(ReadSurfaceMesh(Write("box.stl", AsciiStl(BoxFacets())), 0.001));
  ExpectMillimetreBox(ReadSurfaceMesh(Write("box_binary.STL", BinaryStl(BoxFacets(), 12)), 0.001));
  ExpectMillimetreBox(ReadSurfaceMesh(Write("box.obj", BoxObj()), 0.001));
}

TEST_F(ReadSurfaceMeshTest, SplitsAnObjsQuadsIntoTriangles) {
  const std::string quads =
      "v 0 0 0\nv 10 0 0\nv 0 20 0\nv 10 20 0\nv 0 0 30\nv 10 0 30\nv 0 20 30\nv 10 20 30\n"
      "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  ExpectMillimetreBox(ReadSurfaceMesh(Write("quads.obj", quads), 0.001));
}

TEST_F(ReadSurfaceMeshTest, DropsTrianglesWithTwoCornersAtOnePosition) {
  auto facets = BoxFacets();
  facets.push_back({facets[0][0], facets[0][1], facets[0][1]});  // an exporter's leftover
  ExpectMillimetreBox(ReadSurfaceMesh(Write("leftover.stl", AsciiStl(facets)), 0.001));
}

TEST_F(ReadSurfaceMeshTest, ABinaryStlWhoseHeaderSaysSolidIsStillBinary) {
  std::string bytes = BinaryStl(BoxFacets(), 12);
  bytes.replace(0, 5, "solid");
  ExpectMillimetreBox(ReadSurfaceMesh(Write("solid_header.stl", bytes), 0.001));
}

TEST_F(ReadSurfaceMeshTest, PrintsNothingWhileReading) {
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  ReadSurfaceMesh(Write("box.obj", BoxObj() + "mtllib missing.mtl\nusemtl none\n"));
  EXPECT_THROW(ReadSurfaceMesh(Write("garbage.obj", "f 1 2\nv x y z\n\x01\x02")), Error);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST_F(ReadSurfaceMeshTest, RefusesMissingEmptyAndUnknownFiles) {
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh((dir_ / "absent.stl").string()); }),
                  "no such file");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("empty.stl", "")); }), "is empty");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("box.ply", "ply\nformat ascii 1.0\n")); }),
                  "STL (.stl, ASCII or binary) or OBJ (.obj)");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("box.txt", AsciiStl(BoxFacets()))); }),
                  "not a format hapticsim reads");
  std::filesystem::create_directory(dir_ / "folder.stl");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh((dir_ / "folder.stl").string()); }),
                  "not a regular file");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("box.stl", AsciiStl(BoxFacets())), 0); }),
                  "finite and > 0");
}

TEST_F(ReadSurfaceMeshTest, RefusesATruncatedBinaryStl) {
  auto facets = BoxFacets();
  facets.resize(3);
  const std::string message =
      ErrorOf([&] { ReadSurfaceMesh(Write("truncated.stl", BinaryStl(facets, 12))); });
  EXPECT_MENTIONS(message, "declares 12 triangles (684 bytes) but the file has 234 bytes");
  EXPECT_MENTIONS(message, "truncated");
}

TEST_F(ReadSurfaceMeshTest, RefusesAStlWithANanCoordinate) {
  auto facets = BoxFacets();
  facets[4][1][2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("nan.stl", BinaryStl(facets, 12))); }),
                  "not finite");
  std::string text = AsciiStl(BoxFacets());
  text.replace(text.find("vertex 10 0 0"), 13, "vertex nan 0 0");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("nan_ascii.stl", text)); }), "not finite");
}

TEST_F(ReadSurfaceMeshTest, RefusesAnObjReferringToAMissingVertex) {
  const std::string message = ErrorOf([&] { ReadSurfaceMesh(Write("bad.obj", BoxObj(99))); });
  EXPECT_MENTIONS(message, "bad.obj");
  EXPECT_MENTIONS(message, "refers to vertex 99 on line 11, but has 8 vertices");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("back.obj", "v 0 0 0\nf 1 -2 1\n")); }),
                  "refers to vertex -2 on line 2, but has 1 vertices before it");
}

TEST_F(ReadSurfaceMeshTest, RefusesGarbageAndFilesWithoutTriangles) {
  std::string garbage;
  for (int k = 0; k < 300; ++k) garbage.push_back(static_cast<char>((k * 37 + 11) % 256));
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("garbage.stl", garbage)); }),
                  "neither an ASCII STL");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("garbage.obj", garbage)); }), "garbage.obj");
  // Malformed ASCII STL is refused before Assimp sees it (its reader leaks when it throws).
  std::string two_vertices = AsciiStl(BoxFacets());
  two_vertices.erase(two_vertices.find("      vertex 0 20 0\n"), 20);
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("two.stl", two_vertices)); }),
                  "not a well-formed ASCII STL: 'vertex x y z' expected (line 6)");
  std::string bad_number = AsciiStl(BoxFacets());
  bad_number.replace(bad_number.find("vertex 10 0 0"), 13, "vertex 10 0 0x");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("number.stl", bad_number)); }),
                  "'vertex x y z' expected");
  std::string unfinished = AsciiStl(BoxFacets());
  unfinished.resize(unfinished.find("endsolid"));
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("unfinished.stl", unfinished)); }),
                  "ends before 'endsolid'");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("points.obj", "v 0 0 0\nv 1 0 0\n")); }),
                  "points.obj");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("line.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n")); }),
                  "point or line");
  EXPECT_MENTIONS(ErrorOf([&] { ReadSurfaceMesh(Write("none.stl", BinaryStl({}, 0))); }),
                  "none.stl");
}

TEST_F(ReadSurfaceMeshTest, AnOpenMeshIsReadButRefusedWhenCheckedOrVoxelised) {
  auto facets = BoxFacets();
  facets.pop_back();
  const TriangleMesh mesh = ReadSurfaceMesh(Write("open.stl", AsciiStl(facets)), 0.001);
  EXPECT_EQ(mesh.triangles.size(), 11u);
  EXPECT_MENTIONS(ErrorOf([&] { CheckClosed(mesh); }), "3 edges are open");
  EXPECT_MENTIONS(ErrorOf([&] { VoxeliseClosedSurface(mesh, 0.001); }), "3 edges are open");
}

}  // namespace
}  // namespace hapticsim
