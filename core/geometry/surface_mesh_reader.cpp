#include "core/geometry/surface_mesh_reader.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/geometry/file_text.hpp"

namespace hapticsim {
namespace {

constexpr char kFormatsAccepted[] = "STL (.stl, ASCII or binary) or OBJ (.obj)";

enum class MeshFormat { kStl, kObj };

std::string Quoted(const std::string& path) { return "'" + path + "'"; }

MeshFormat FormatOf(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (EndsWithIgnoringCase(path, ".stl")) return MeshFormat::kStl;
  if (EndsWithIgnoringCase(path, ".obj")) return MeshFormat::kObj;
  throw Error("surface mesh " + Quoted(path) + " is not a format hapticsim reads (extension '" +
              extension + "'): export it as " + kFormatsAccepted);
}

std::string ReadBytes(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw Error(
        "cannot read surface mesh " + Quoted(path) + ": " +
        (std::filesystem::exists(path, error) ? "it is not a regular file" : "no such file"));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read surface mesh " + Quoted(path) + ": " + std::strerror(errno));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error("cannot read surface mesh " + Quoted(path) + ": read error");
  HAPTICSIM_THROW_UNLESS(!bytes.empty(), "surface mesh " + Quoted(path) + " is empty");
  return bytes;
}

bool LooksLikeAsciiStl(const std::string& bytes) {
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  if (start == std::string::npos || bytes.compare(start, 5, "solid") != 0) return false;
  // Binary headers often begin with "solid" too; an ASCII STL is printable ASCII and line ends.
  return std::all_of(bytes.begin(), bytes.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return (byte >= 0x20 && byte < 0x7f) || byte == '\t' || byte == '\n' || byte == '\r';
  });
}

std::vector<std::string_view> WordsOf(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t begin = line.find_first_not_of(" \t");
  while (begin != std::string_view::npos) {
    const std::size_t end = std::min(line.find_first_of(" \t", begin), line.size());
    words.push_back(line.substr(begin, end - begin));
    begin = line.find_first_not_of(" \t", end);
  }
  return words;
}

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

/// A number as Assimp's fast_atoreal_move reads it whole: [+-] digits [. digits] [e [+-] digits],
/// or nan / inf / infinity (any case). Anything else makes it throw, or read the next word.
bool IsStlNumber(std::string_view word) {
  std::size_t i = (!word.empty() && (word[0] == '+' || word[0] == '-')) ? 1 : 0;
  std::string lower(word.substr(i));
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "nan" || lower == "inf" || lower == "infinity") return true;
  const auto digits = [&] {
    const std::size_t from = i;
    while (i < word.size() && IsDigit(word[i])) ++i;
    return i - from;
  };
  const std::size_t whole = digits();
  std::size_t fraction = 0;
  if (i < word.size() && word[i] == '.') {
    ++i;
    fraction = digits();
  }
  if (whole + fraction == 0) return false;
  if (i < word.size() && (word[i] == 'e' || word[i] == 'E')) {
    ++i;
    if (i < word.size() && (word[i] == '+' || word[i] == '-')) ++i;
    const std::size_t exponent = digits();
    if (exponent == 0 || exponent > 4) return false;
  }
  return i == word.size();
}

/// Whether `words` are `keyword` followed by three numbers (a vertex or a facet's normal).
bool IsKeywordAndPoint(const std::vector<std::string_view>& words,
                       std::initializer_list<std::string_view> keyword) {
  if (words.size() != keyword.size() + 3) return false;
  if (!std::equal(keyword.begin(), keyword.end(), words.begin())) return false;
  return std::all_of(words.end() - 3, words.end(), IsStlNumber);
}

/// What is wrong with a line that should open a solid, or "".
std::string SolidLineError(const std::vector<std::string_view>& words) {
  if (words[0] != "solid") return "'solid' expected";
  for (std::size_t k = 1; k < words.size(); ++k) {
    // Assimp takes the name's first word only, and reads the rest of the line as statements.
    for (std::string_view keyword : {"facet", "vertex", "endsolid"}) {
      if (words[k].substr(0, keyword.size()) == keyword) {
        return "a solid's name must not contain '" + std::string(keyword) + "'";
      }
    }
    if (words[k].size() > 1000) return "a solid's name of over 1000 characters";
  }
  return "";
}

/// A facet's lines after 'facet normal': outer loop, three vertices, endloop, endfacet.
constexpr std::size_t kFacetBodyLines = 6;

/// What is wrong with line `body_line` (0 to 5) of a facet's body, or "".
std::string FacetBodyLineError(const std::vector<std::string_view>& words, std::size_t body_line) {
  static const std::vector<std::string_view> kFixedLines[kFacetBodyLines] = {
      {"outer", "loop"}, {}, {}, {}, {"endloop"}, {"endfacet"}};
  if (body_line >= 1 && body_line <= 3) {
    return IsKeywordAndPoint(words, {"vertex"}) ? "" : "'vertex x y z' expected";
  }
  if (words == kFixedLines[body_line]) return "";
  std::string expected = "'";
  for (std::string_view word : kFixedLines[body_line]) {
    if (expected.size() > 1) expected.push_back(' ');
    expected.append(word);
  }
  return expected + "' expected";
}

/// The ASCII STL grammar, one statement a line (Assimp 5.2 reads a statement's numbers on its
/// line only):  solid [name] / { facet normal n n n / outer loop / vertex x y z (3 times) /
/// endloop / endfacet }+ / endsolid [name], and again for each further solid. Checked here
/// because Assimp's reader leaks its meshes whenever it throws (a facet without three vertices
/// or a normal, a malformed number, a name of 1024 characters): it must never have to.
/// @returns what is wrong and on which line, or "" when the text follows the grammar.
std::string AsciiStlGrammarError(const std::string& text) {
  enum class Expect { kSolid, kFacetOrEndsolid, kFacetBody } expect = Expect::kSolid;
  std::size_t body_line = 0, facets_in_solid = 0, line_number = 0;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string_view> words = WordsOf(line);
    if (words.empty()) continue;
    std::string error;
    if (expect == Expect::kSolid) {
      error = SolidLineError(words);
      expect = Expect::kFacetOrEndsolid;
      facets_in_solid = 0;
    } else if (expect == Expect::kFacetOrEndsolid) {
      if (words[0] == "endsolid") {
        if (facets_in_solid == 0) error = "a solid without facets";
        expect = Expect::kSolid;
      } else if (IsKeywordAndPoint(words, {"facet", "normal"})) {
        expect = Expect::kFacetBody;
        body_line = 0;
      } else {
        error = "'facet normal nx ny nz' or 'endsolid' expected";
      }
    } else {
      error = FacetBodyLineError(words, body_line);
      if (++body_line == kFacetBodyLines) {
        ++facets_in_solid;
        expect = Expect::kFacetOrEndsolid;
      }
    }
    if (!error.empty()) return error + " (line " + std::to_string(line_number) + ")";
  }
  return expect == Expect::kSolid ? "" : "the text ends before 'endsolid': it is truncated";
}

/// A binary STL is an 80-byte header, a triangle count n and n records of 50 bytes; any other
/// file must be a well-formed ASCII STL. Checked here: Assimp takes a binary file of the wrong
/// size for ASCII and reports a confusing error, and leaks on a malformed ASCII one.
void CheckStlLayout(const std::string& bytes, const std::string& path) {
  constexpr std::uint64_t kHeaderBytes = 84, kTriangleBytes = 50;
  std::uint32_t declared = 0;
  if (bytes.size() >= kHeaderBytes) std::memcpy(&declared, bytes.data() + 80, 4);  // little-endian
  const std::uint64_t expected = kHeaderBytes + kTriangleBytes * declared;
  if (bytes.size() >= kHeaderBytes && bytes.size() == expected) return;
  if (LooksLikeAsciiStl(bytes)) {
    const std::string error = AsciiStlGrammarError(bytes);
    HAPTICSIM_THROW_UNLESS(error.empty(), "surface mesh " + Quoted(path) +
                                              " is not a well-formed ASCII STL: " + error);
    return;
  }
  std::ostringstream message;
  message << "surface mesh " << Quoted(path) << " is neither an ASCII STL (text starting with "
          << "'solid') nor a whole binary STL: ";
  if (bytes.size() < kHeaderBytes) {
    message << "its " << bytes.size() << " bytes are fewer than a binary STL's 84-byte header";
  } else {
    message << "its header declares " << declared << " triangles (" << expected
            << " bytes) but the file has " << bytes.size() << " bytes"
            << (bytes.size() < expected ? ": it is truncated" : "");
  }
  throw Error(message.str());
}

struct ObjStatement {
  std::size_t line;  ///< 1-based, where it starts
  std::string text;
};

/// The OBJ's statements, one a line, lines ending in '\\' joined to the next as Assimp does.
std::vector<ObjStatement> ObjStatements(const std::string& text) {
  std::vector<ObjStatement> statements = {{1, ""}};
  std::istringstream lines(text);
  std::size_t line_number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const bool continued = !line.empty() && line.back() == '\\';
    if (continued) line.back() = ' ';
    statements.back().text += line;
    if (!continued) statements.push_back({line_number + 1, ""});
  }
  return statements;
}

/// Whether a 'v' statement defines a vertex for Assimp: 3, 4 or 6 numbers (it counts words that
/// start with a digit or sign, or nan / inf) before any '#'.
bool DefinesObjVertex(std::string_view statement) {
  if (statement.size() < 2 || statement[0] != 'v' ||
      (statement[1] != ' ' && statement[1] != '\t')) {
    return false;
  }
  std::size_t numbers = 0;
  for (std::string_view word : WordsOf(statement.substr(1, statement.find('#') - 1))) {
    const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(word[0])));
    numbers += IsDigit(c) || c == '+' || c == '-' || c == 'n' || c == 'i';
  }
  return numbers == 3 || numbers == 4 || numbers == 6;
}

/// The vertex indices of a face, line or point statement as written (1-based, or negative
/// counting back); none for any other statement, or a corner Assimp itself refuses.
std::vector<long long> ObjCornerIndices(std::string_view statement) {
  std::vector<long long> indices;
  if (statement.size() < 2 ||
      std::string_view("fpl").find(statement[0]) == std::string_view::npos ||
      (statement[1] != ' ' && statement[1] != '\t')) {
    return indices;
  }
  for (std::string_view corner : WordsOf(statement.substr(1, statement.find('#') - 1))) {
    const std::string vertex(corner.substr(0, corner.find('/')));
    char* end = nullptr;
    errno = 0;
    const long long index = std::strtoll(vertex.c_str(), &end, 10);
    if (!vertex.empty() && *end == '\0' && errno == 0 && index != 0) indices.push_back(index);
  }
  return indices;
}

/// Refuses a face, line or point whose vertex index is out of range: a positive one beyond the
/// file's vertices, a negative one before the first. Checked here because Assimp 5.2's OBJ
/// reader leaks its mesh when it finds one (and this message names the line).
void CheckObjVertexIndices(const std::string& text, const std::string& path) {
  const std::vector<ObjStatement> statements = ObjStatements(text);
  const long long total = std::count_if(statements.begin(), statements.end(),
                                        [](const auto& s) { return DefinesObjVertex(s.text); });
  long long so_far = 0;
  for (const ObjStatement& statement : statements) {
    so_far += DefinesObjVertex(statement.text);
    for (long long index : ObjCornerIndices(statement.text)) {
      const bool in_range = index > 0 ? index <= total : -index <= so_far;
      HAPTICSIM_THROW_UNLESS(
          in_range, "surface mesh " + Quoted(path) + " refers to vertex " + std::to_string(index) +
                        " on line " + std::to_string(statement.line) + ", but has " +
                        std::to_string(index > 0 ? total : so_far) + " vertices" +
                        (index > 0 ? "" : " before it") + ": vertex index out of range");
    }
  }
}

/// Lets Assimp open no file but the one in memory: an OBJ's `mtllib` must not make it read
/// another file (materials do not matter here, and a path such as /dev/zero would never end).
class NoFilesystem : public Assimp::IOSystem {
 public:
  bool Exists(const char*) const override { return false; }
  char getOsSeparator() const override { return '/'; }
  Assimp::IOStream* Open(const char*, const char*) override { return nullptr; }
  void Close(Assimp::IOStream* stream) override { delete stream; }
};

bool IsIdentity(const aiMatrix4x4& m) {
  const aiMatrix4x4 identity;
  for (unsigned row = 0; row < 4; ++row) {
    for (unsigned column = 0; column < 4; ++column) {
      if (m[row][column] != identity[row][column]) return false;
    }
  }
  return true;
}

/// STL and OBJ define no transforms, so the meshes' coordinates are the file's; a node that
/// moves its meshes would mean Assimp read something else, and is refused rather than applied.
void CheckNoTransforms(const aiScene& scene, const std::string& path) {
  std::vector<const aiNode*> pending = {scene.mRootNode};
  while (!pending.empty()) {
    const aiNode* node = pending.back();
    pending.pop_back();
    if (node == nullptr) continue;
    HAPTICSIM_THROW_UNLESS(IsIdentity(node->mTransformation),
                           "surface mesh " + Quoted(path) +
                               " places its triangles with a transform, which " + kFormatsAccepted +
                               " files do not have");
    pending.insert(pending.end(), node->mChildren, node->mChildren + node->mNumChildren);
  }
}

using Corner = std::array<double, 3>;

/// Every triangle's corners in metres, three per triangle, from all meshes of the scene.
std::vector<Corner> TriangleCorners(const aiScene& scene, const std::string& path,
                                    double metres_per_unit) {
  std::vector<Corner> corners;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      HAPTICSIM_THROW_UNLESS(face.mNumIndices == 3,
                             "surface mesh " + Quoted(path) + " has a point or line (a face of " +
                                 std::to_string(face.mNumIndices) +
                                 " corners): only triangles and polygons bound a volume");
      for (unsigned k = 0; k < 3; ++k) {
        const unsigned index = face.mIndices[k];
        HAPTICSIM_THROW_UNLESS(index < mesh.mNumVertices, "surface mesh " + Quoted(path) +
                                                              " refers to vertex " +
                                                              std::to_string(index + 1) + " of " +
                                                              std::to_string(mesh.mNumVertices));
        const aiVector3D& v = mesh.mVertices[index];
        const Corner corner = {v.x * metres_per_unit, v.y * metres_per_unit, v.z * metres_per_unit};
        if (!std::isfinite(corner[0]) || !std::isfinite(corner[1]) || !std::isfinite(corner[2])) {
          std::ostringstream message;
          message << "surface mesh " << Quoted(path) << " has a coordinate that is not finite"
                  << " (in metres: " << corner[0] << ", " << corner[1] << ", " << corner[2] << ")";
          throw Error(message.str());
        }
        corners.push_back(corner);
      }
    }
  }
  return corners;
}

/// Joins corners at exactly one position into one vertex (numbered in order of first use) and
/// drops triangles with two corners at one position: they bound nothing, and dropping one
/// removes its edge twice, so it never opens the surface. (Assimp's own joining compares normals
/// too, and an STL gives each facet its own, so it would not join a cube's corners anyway.)
TriangleMesh JoinCorners(const std::vector<Corner>& corners) {
  std::vector<std::size_t> order(corners.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return corners[a] < corners[b]; });
  std::vector<std::size_t> first_at_position(corners.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const bool same = k > 0 && !(corners[order[k - 1]] < corners[order[k]]);
    first_at_position[order[k]] = same ? first_at_position[order[k - 1]] : order[k];
  }
  TriangleMesh mesh;
  std::vector<int> vertex_of_corner(corners.size(), -1);
  for (std::size_t t = 0; t + 2 < corners.size(); t += 3) {
    std::array<int, 3> triangle{};
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t first = first_at_position[t + k];
      if (vertex_of_corner[first] < 0) {
        vertex_of_corner[first] = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(corners[first]);
      }
      triangle[k] = vertex_of_corner[first];
    }
    if (triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[2] == triangle[0]) {
      continue;
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

const aiScene& Import(Assimp::Importer& importer, const std::string& bytes, const std::string& path,
                      MeshFormat format) {
  // Assimp logs only through DefaultLogger, which is a NullLogger unless someone creates one;
  // none is created here, so reading prints nothing.
  importer.SetIOHandler(new NoFilesystem);  // the importer owns it
  // No aiProcess_JoinIdenticalVertices: it compares with a tolerance and mishandles NaN (a
  // corner at NaN was merged into a finite one and vanished), so JoinCorners joins exactly.
  const unsigned flags = aiProcess_Triangulate | aiProcess_ValidateDataStructure;
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags,
                                        format == MeshFormat::kStl ? "stl" : "obj");
  } catch (const std::exception& error) {  // Assimp catches its own; in case one escapes
    throw Error("cannot read surface mesh " + Quoted(path) + ": " + error.what());
  }
  HAPTICSIM_THROW_UNLESS(scene != nullptr && scene->mRootNode != nullptr,
                         "cannot read surface mesh " + Quoted(path) + " as " +
                             (format == MeshFormat::kStl ? "STL" : "OBJ") + ": " +
                             importer.GetErrorString());
  return *scene;
}

}  // namespace

TriangleMesh ReadSurfaceMesh(const std::string& path, double metres_per_unit) {
  HAPTICSIM_THROW_UNLESS(std::isfinite(metres_per_unit) && metres_per_unit > 0,
                         "the metres per unit of surface mesh " + Quoted(path) +
                             " must be finite and > 0 (0.001 for a mesh in millimetres), not " +
                             FormatFileNumber(metres_per_unit));
  const MeshFormat format = FormatOf(path);
  const std::string bytes = ReadBytes(path);
  if (format == MeshFormat::kStl) CheckStlLayout(bytes, path);
  if (format == MeshFormat::kObj) CheckObjVertexIndices(bytes, path);
  Assimp::Importer importer;
  const aiScene& scene = Import(importer, bytes, path, format);
  CheckNoTransforms(scene, path);
  const std::vector<Corner> corners = TriangleCorners(scene, path, metres_per_unit);
  HAPTICSIM_THROW_UNLESS(corners.size() / 3 <= std::numeric_limits<int>::max() / 3,
                         "surface mesh " + Quoted(path) + " has too many triangles");
  TriangleMesh mesh = JoinCorners(corners);
  HAPTICSIM_THROW_UNLESS(!mesh.triangles.empty(),
                         "surface mesh " + Quoted(path) + " has no triangles (of non-zero size)");
  return mesh;
}

}  // namespace hapticsim
