#include "core/geometry/nifti_reader.hpp"

#include <nifti2_io.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/geometry/file_text.hpp"
#include "core/geometry/voxel_resampling.hpp"

// How the work is split between libnifti2 and this file, and why:
//  - libnifti2 reads the header bytes and the voxel data (it knows .nii.gz), converts the header
//    into a nifti_image (byte order, the qform's quaternion) and byte-swaps the data.
//  - Everything it would trust blindly is checked here first, from the raw header bytes: its
//    converter quietly turns a dim of 0 into 1 and a NaN pixdim into 1, casts vox_offset to int,
//    and nifti_image_load callocs whatever the dims claim before finding the data is not there.
//    So the dims, the data's presence and the output's size are all settled before anything
//    proportional to the volume is allocated: at most the data really in the file (decompressed),
//    its labels, and an output lattice of at most kMaxSourceVoxels.
//  - Its extension reader is never entered (it allocates what the file claims), nor its ASCII
//    (.nia) header path for a .nii (it leaks; for a .nii.gz it refuses ASCII before allocating).
//  - Its data reader replaces NaN and infinite floats by 0 (outside) without saying so: such a
//    float label volume reads with those voxels empty.

namespace hapticsim {
namespace {

/// Data further into the file than this is a corrupt header, not a real extension block.
constexpr std::int64_t kMaxVoxOffsetBytes = std::int64_t{1} << 32;

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw Error("NIfTI file '" + path + "': " + what);
}

struct NiftiFile {
  int version = 0;                    ///< 1 or 2
  bool gzipped = false;               ///< .nii.gz
  std::vector<unsigned char> header;  ///< the raw header bytes as stored (348 or 540)
};

/// The header fields the reader uses, in native byte order.
struct HeaderFields {
  std::array<std::int64_t, 8> dim{};
  std::array<double, 8> pixdim{};
  int datatype = 0;
  double vox_offset = 0;  ///< bytes from the start of the (decompressed) file to the data
  double scl_slope = 0, scl_inter = 0;
  int xyzt_units = 0;
  int qform_code = 0, sform_code = 0;
};

struct LabelType {
  int code;
  int bytes;
  const char* name;
};

constexpr std::array<LabelType, 10> kLabelTypes = {{{DT_UINT8, 1, "uint8"},
                                                    {DT_INT8, 1, "int8"},
                                                    {DT_UINT16, 2, "uint16"},
                                                    {DT_INT16, 2, "int16"},
                                                    {DT_UINT32, 4, "uint32"},
                                                    {DT_INT32, 4, "int32"},
                                                    {DT_UINT64, 8, "uint64"},
                                                    {DT_INT64, 8, "int64"},
                                                    {DT_FLOAT32, 4, "float32"},
                                                    {DT_FLOAT64, 8, "float64"}}};

const LabelType* FindLabelType(int datatype) {
  for (const LabelType& type : kLabelTypes) {
    if (type.code == datatype) return &type;
  }
  return nullptr;
}

/// Refuses what libnifti2 would misread: another extension (it would go looking for
/// .hdr/.img pairs), a directory or FIFO, a short file, and the non-standard ASCII header.
void CheckFileBeforeTheLibrary(const std::string& path, bool gzipped) {
  if (!EndsWithIgnoringCase(path, ".nii") && !gzipped) {
    Fail(path, "hapticsim reads single-file NIfTI volumes: name it .nii or .nii.gz");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    Fail(path, "no such file (or not a regular file): check geometry.file");
  }
  if (gzipped) return;  // its size and first bytes are known only once decompressed
  if (std::filesystem::file_size(path, error) < sizeof(nifti_1_header)) {
    Fail(path,
         "the file is shorter than the 348-byte NIfTI header: it is truncated or not "
         "NIfTI; export the segmentation again");
  }
  char start[12] = {};
  std::ifstream(path, std::ios::binary).read(start, sizeof(start));
  if (std::memcmp(start, "<nifti_image", sizeof(start)) == 0) {
    Fail(path, "ASCII NIfTI headers are not supported: export a binary .nii");
  }
  std::int32_t header_size;
  std::memcpy(&header_size, start, sizeof(header_size));
  const bool nifti2 = header_size == 540 || header_size == 0x1C020000;  // either byte order
  if (nifti2 && std::filesystem::file_size(path, error) < sizeof(nifti_2_header)) {
    Fail(path,
         "the file is shorter than the 540-byte NIfTI-2 header: it is truncated; export "
         "the segmentation again");
  }
}

NiftiFile ReadRawHeader(const std::string& path) {
  NiftiFile file;
  file.gzipped = EndsWithIgnoringCase(path, ".nii.gz");
  CheckFileBeforeTheLibrary(path, file.gzipped);
  int version = -1;
  const std::unique_ptr<void, decltype(&std::free)> raw(
      nifti_read_header(path.c_str(), &version, 0 /* no check: we check */), &std::free);
  if (raw == nullptr) {
    Fail(path, std::string("cannot read a NIfTI header: the file is shorter than the header") +
                   (file.gzipped ? " or not a valid gzip stream" : "") +
                   "; export the segmentation again");
  }
  if (version == 0) {
    Fail(path, "an ANALYZE 7.5 header (no NIfTI magic): export the segmentation as NIfTI");
  }
  if (version != 1 && version != 2) {
    Fail(path, "not a NIfTI-1 or NIfTI-2 file (no valid header size and magic)");
  }
  file.version = version;
  const std::size_t size = version == 1 ? sizeof(nifti_1_header) : sizeof(nifti_2_header);
  const auto* bytes = static_cast<const unsigned char*>(raw.get());
  file.header.assign(bytes, bytes + size);
  return file;
}

template <typename Field>
Field ReadField(const std::vector<unsigned char>& header, std::size_t offset, bool swapped) {
  std::array<unsigned char, sizeof(Field)> bytes;
  std::memcpy(bytes.data(), header.data() + offset, sizeof(Field));
  if (swapped) std::reverse(bytes.begin(), bytes.end());
  Field value;
  std::memcpy(&value, bytes.data(), sizeof(Field));
  return value;
}

/// True when the header was written in the other byte order (its sizeof_hdr reads swapped).
bool IsSwapped(const NiftiFile& file) {
  const int expected = file.version == 1 ? 348 : 540;
  return ReadField<std::int32_t>(file.header, 0, false) != expected;
}

/// Reads the fields of a NIfTI-1 (Header = nifti_1_header, narrow types) or NIfTI-2 header.
template <typename Header, typename Dim, typename Real, typename Code, typename Units>
HeaderFields ReadFields(const NiftiFile& file) {
  const bool swapped = IsSwapped(file);
  const auto& h = file.header;
  HeaderFields fields;
  for (std::size_t i = 0; i < 8; ++i) {
    fields.dim[i] = ReadField<Dim>(h, offsetof(Header, dim) + i * sizeof(Dim), swapped);
    fields.pixdim[i] = ReadField<Real>(h, offsetof(Header, pixdim) + i * sizeof(Real), swapped);
  }
  fields.datatype = ReadField<std::int16_t>(h, offsetof(Header, datatype), swapped);
  fields.vox_offset = static_cast<double>(
      ReadField<decltype(Header::vox_offset)>(h, offsetof(Header, vox_offset), swapped));
  fields.scl_slope = ReadField<Real>(h, offsetof(Header, scl_slope), swapped);
  fields.scl_inter = ReadField<Real>(h, offsetof(Header, scl_inter), swapped);
  fields.xyzt_units = ReadField<Units>(h, offsetof(Header, xyzt_units), swapped);
  fields.qform_code = ReadField<Code>(h, offsetof(Header, qform_code), swapped);
  fields.sform_code = ReadField<Code>(h, offsetof(Header, sform_code), swapped);
  return fields;
}

HeaderFields ReadHeaderFields(const std::string& path, const NiftiFile& file) {
  // A two-file pair's magic ("ni1") would send libnifti2 looking for a separate .img file.
  const char one_file_mark = static_cast<char>(file.header[offsetof(nifti_1_header, magic) + 1]);
  const char n2_mark = static_cast<char>(file.header[offsetof(nifti_2_header, magic) + 1]);
  if ((file.version == 1 ? one_file_mark : n2_mark) != '+') {
    Fail(path, "the header is of a .hdr/.img pair: convert it to a single .nii file");
  }
  if (file.version == 1) {
    return ReadFields<nifti_1_header, std::int16_t, float, std::int16_t, std::uint8_t>(file);
  }
  return ReadFields<nifti_2_header, std::int64_t, double, std::int32_t, std::int32_t>(file);
}

/// The voxel counts, after checking the header describes a 3-D volume hapticsim can hold.
std::array<int, 3> CheckDimensions(const std::string& path, const HeaderFields& fields) {
  const std::int64_t dims = fields.dim[0];
  if (dims != 3 && !(dims == 4 && fields.dim[4] == 1)) {
    Fail(path, "a " + std::to_string(dims) +
                   "-D volume (dim[0]); a label volume is 3-D (or 4-D with one time point): "
                   "export the segmentation as one 3-D volume");
  }
  std::size_t total = 1;
  std::array<int, 3> voxels{};
  for (int axis = 0; axis < 3; ++axis) {
    const std::int64_t count = fields.dim[axis + 1];
    if (count < 1) {
      Fail(path, "dim[" + std::to_string(axis + 1) + "] is " + std::to_string(count) +
                     ": every dimension needs at least one voxel");
    }
    // Each factor and the running product stay ≤ 2^28, so the product cannot overflow.
    if (static_cast<std::uint64_t>(count) > kMaxSourceVoxels ||
        total * static_cast<std::size_t>(count) > kMaxSourceVoxels) {
      Fail(path, "the volume is " + std::to_string(fields.dim[1]) + " x " +
                     std::to_string(fields.dim[2]) + " x " + std::to_string(fields.dim[3]) +
                     " voxels, more than the " + std::to_string(kMaxSourceVoxels) +
                     " hapticsim reads: crop or downsample the segmentation");
    }
    total *= static_cast<std::size_t>(count);
    voxels[axis] = static_cast<int>(count);
  }
  return voxels;
}

void CheckPixdims(const std::string& path, const HeaderFields& fields) {
  for (int axis = 1; axis <= 3; ++axis) {
    const double edge = fields.pixdim[axis];
    if (!std::isfinite(edge) || edge <= 0) {
      Fail(path, "pixdim[" + std::to_string(axis) + "] is " + FormatFileNumber(edge) +
                     ": voxel sizes must be finite and > 0");
    }
  }
}

/// The data type's size in bytes, after checking it can hold labels.
int CheckDataType(const std::string& path, const HeaderFields& fields) {
  const LabelType* type = FindLabelType(fields.datatype);
  if (type == nullptr) {
    const char* name = nifti_datatype_string(fields.datatype);
    Fail(path, std::string("voxels of type ") + name + " (datatype " +
                   std::to_string(fields.datatype) +
                   ") cannot be labels: export the segmentation as integers (uint8, int16, ...)");
  }
  const bool unscaled = fields.scl_slope == 0 || (fields.scl_slope == 1 && fields.scl_inter == 0);
  if (!unscaled) {
    Fail(path, "the voxel values are scaled (scl_slope " + FormatFileNumber(fields.scl_slope) +
                   ", scl_inter " + FormatFileNumber(fields.scl_inter) +
                   "); labels must be stored as they are: export without scaling "
                   "(scl_slope 0 or 1, scl_inter 0)");
  }
  return type->bytes;
}

std::int64_t CheckVoxOffset(const std::string& path, const NiftiFile& file,
                            const HeaderFields& fields) {
  const double header_bytes = static_cast<double>(file.header.size());
  const double offset = fields.vox_offset;
  if (!(offset >= header_bytes && offset <= static_cast<double>(kMaxVoxOffsetBytes) &&
        offset == std::floor(offset))) {
    Fail(path, "vox_offset " + FormatFileNumber(offset) + " is not a whole number of bytes from " +
                   FormatFileNumber(header_bytes) + " to 2^32: the header is corrupt");
  }
  return static_cast<std::int64_t>(offset);
}

/// Metres per unit of the header's lengths (xyzt_units; none named means millimetres).
double MetresPerUnit(const std::string& path, const HeaderFields& fields) {
  switch (fields.xyzt_units & 0x07) {
    case NIFTI_UNITS_UNKNOWN:  // what most segmentation tools mean: the NIfTI convention
    case NIFTI_UNITS_MM:
      return 1e-3;
    case NIFTI_UNITS_METER:
      return 1.0;
    case NIFTI_UNITS_MICRON:
      return 1e-6;
    default:
      Fail(path, "xyzt_units " + std::to_string(fields.xyzt_units) +
                     " names no spatial unit: use metres, millimetres or microns");
  }
}

struct NiftiImageDeleter {
  void operator()(nifti_image* image) const { nifti_image_free(image); }
};
using NiftiImagePtr = std::unique_ptr<nifti_image, NiftiImageDeleter>;

NiftiImagePtr ConvertHeader(const std::string& path, const NiftiFile& file) {
  nifti_image* image = nullptr;
  if (file.version == 1) {
    nifti_1_header header;
    std::memcpy(&header, file.header.data(), sizeof(header));
    image = nifti_convert_n1hdr2nim(header, path.c_str());
  } else {
    nifti_2_header header;
    std::memcpy(&header, file.header.data(), sizeof(header));
    image = nifti_convert_n2hdr2nim(header, path.c_str());
  }
  if (image == nullptr) Fail(path, "libnifti2 cannot make sense of the header");
  return NiftiImagePtr(image);
}

/// The sform if it is set, else the qform, else the pixdims: as NIfTI's "method 3, 2, 1".
VoxelAffine ChooseAffine(const std::string& path, const nifti_image& image, double metres_per_unit) {
  VoxelAffine affine;
  const nifti_dmat44* matrix = &image.qto_xyz;  // pixdim scaling when qform_code is 0
  affine.source = image.qform_code > 0 ? "qform" : "pixdim";
  if (image.sform_code > 0) {
    matrix = &image.sto_xyz;
    affine.source = "sform";
  }
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      affine.linear[row][column] = matrix->m[row][column] * metres_per_unit;
    }
    affine.translation[row] = matrix->m[row][3] * metres_per_unit;
    for (int column = 0; column < 4; ++column) {
      if (!std::isfinite(matrix->m[row][column])) {
        Fail(path, std::string("the ") + affine.source +
                       " has a non-finite entry: fix the header's orientation");
      }
    }
  }
  return affine;
}

/// Makes sure the file really holds the data its header declares before libnifti2 callocs it.
void CheckDataPresent(const std::string& path, const NiftiFile& file, nifti_image* image,
                      std::int64_t offset, std::int64_t data_bytes) {
  // libnifti2 reads the data from the file it finds for the header's name: a sibling foo.nii
  // wins over foo.nii.gz, and a NIfTI-2 foo.nii looks for foo.img first.
  const std::unique_ptr<char, decltype(&std::free)> data_file(
      nifti_findimgname(image->iname, image->nifti_type), &std::free);
  if (data_file == nullptr || path != data_file.get()) {
    Fail(path, std::string("libnifti2 would read the voxel data from '") +
                   (data_file ? data_file.get() : "(nothing)") +
                   "' instead: move the file away from files of the same name");
  }
  if (!file.gzipped) {
    std::error_code error;
    const auto size = std::filesystem::file_size(path, error);
    if (error || size < static_cast<std::uintmax_t>(offset + data_bytes)) {
      Fail(path, "the file is truncated: its header declares " + std::to_string(data_bytes) +
                     " bytes of voxel data from byte " + std::to_string(offset) + ", but it is " +
                     std::to_string(size) + " bytes long; export the segmentation again");
    }
    return;
  }
  // A .nii.gz's length is known only by decompressing it: read its last voxel alone first.
  std::array<std::int64_t, 8> last_voxel = {
      0, image->nx - 1, image->ny - 1, image->nz - 1, -1, -1, -1, -1};
  void* voxel = nullptr;
  const std::int64_t read = nifti_read_collapsed_image(image, last_voxel.data(), &voxel);
  std::free(voxel);
  if (read <= 0) {
    Fail(path, "the file is truncated or its gzip stream is corrupt: it does not hold the " +
                   std::to_string(data_bytes) +
                   " bytes of voxel data its header declares; export the segmentation again");
  }
}

template <typename Value>
bool IsLabel(Value value) {
  if constexpr (std::is_floating_point_v<Value>) {
    return value >= 0 && value <= 65535 && value == std::floor(value);  // NaN fails
  } else if constexpr (std::is_signed_v<Value>) {
    return value >= 0 && value <= 65535;
  } else {
    return value <= 65535;
  }
}

template <typename Value>
[[noreturn]] void FailOnLabel(const std::string& path, Value value, std::size_t index,
                              const std::array<int, 3>& voxels) {
  const std::size_t x = index % voxels[0];
  const std::size_t y = index / voxels[0] % voxels[1];
  const std::size_t z = index / voxels[0] / voxels[1];
  std::ostringstream text;
  text.precision(17);
  text << +value;  // + prints 8-bit values as numbers
  Fail(path, "voxel (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) +
                 ") holds " + text.str() +
                 ", not a label: labels are whole numbers 0..65535 (0 = outside)");
}

template <typename Value>
std::vector<std::uint16_t> ToLabels(const std::string& path, const void* data,
                                    const std::array<int, 3>& voxels) {
  const std::size_t count = static_cast<std::size_t>(voxels[0]) * voxels[1] * voxels[2];
  const auto* values = static_cast<const Value*>(data);
  std::vector<std::uint16_t> labels(count);
  for (std::size_t i = 0; i < count; ++i) {
    if (!IsLabel(values[i])) FailOnLabel(path, values[i], i, voxels);
    labels[i] = static_cast<std::uint16_t>(values[i]);
  }
  return labels;
}

std::vector<std::uint16_t> ReadLabels(const std::string& path, nifti_image* image,
                                      const std::array<int, 3>& voxels) {
  if (nifti_image_load(image) != 0) {
    Fail(path,
         "cannot read the voxel data: the file is truncated or corrupt; export the "
         "segmentation again");
  }
  const void* data = image->data;
  std::vector<std::uint16_t> labels;
  switch (image->datatype) {
    case DT_UINT8:
      labels = ToLabels<std::uint8_t>(path, data, voxels);
      break;
    case DT_INT8:
      labels = ToLabels<std::int8_t>(path, data, voxels);
      break;
    case DT_UINT16:
      labels = ToLabels<std::uint16_t>(path, data, voxels);
      break;
    case DT_INT16:
      labels = ToLabels<std::int16_t>(path, data, voxels);
      break;
    case DT_UINT32:
      labels = ToLabels<std::uint32_t>(path, data, voxels);
      break;
    case DT_INT32:
      labels = ToLabels<std::int32_t>(path, data, voxels);
      break;
    case DT_UINT64:
      labels = ToLabels<std::uint64_t>(path, data, voxels);
      break;
    case DT_INT64:
      labels = ToLabels<std::int64_t>(path, data, voxels);
      break;
    case DT_FLOAT32:
      labels = ToLabels<float>(path, data, voxels);
      break;
    case DT_FLOAT64:
      labels = ToLabels<double>(path, data, voxels);
      break;
    default:
      Fail(path, "unexpected datatype " + std::to_string(image->datatype));
  }
  nifti_image_unload(image);  // the raw data is no longer needed: free it before resampling
  return labels;
}

}  // namespace

LabelVolume ReadNiftiLabels(const std::string& path, double spacing_m) {
  nifti_set_debug_level(0);  // its remaining messages on failure cannot be turned off
  const NiftiFile file = ReadRawHeader(path);
  const HeaderFields fields = ReadHeaderFields(path, file);
  const std::array<int, 3> voxels = CheckDimensions(path, fields);
  CheckPixdims(path, fields);
  const int bytes_per_voxel = CheckDataType(path, fields);
  const std::int64_t offset = CheckVoxOffset(path, file, fields);
  const double metres_per_unit = MetresPerUnit(path, fields);

  // The header is sane: libnifti2 may now convert it (orientation matrices) and read the data.
  const NiftiImagePtr image = ConvertHeader(path, file);
  const std::int64_t source_voxels = std::int64_t{voxels[0]} * voxels[1] * voxels[2];
  if (image->nvox != source_voxels || image->nbyper != bytes_per_voxel ||
      image->iname_offset != offset) {
    Fail(path, "libnifti2 reads the header differently from hapticsim: the header is corrupt");
  }
  const VoxelAffine affine = ChooseAffine(path, *image, metres_per_unit);
  LabelVolume lattice;
  try {
    InvertLinear(affine);  // a singular header is refused before its data is read
    lattice = PlanLattice(affine, voxels, ChooseSpacing(affine, spacing_m));
  } catch (const Error& error) {
    Fail(path, error.what());
  }

  CheckDataPresent(path, file, image.get(), offset, source_voxels * bytes_per_voxel);
  const std::vector<std::uint16_t> labels = ReadLabels(path, image.get(), voxels);
  ResampleNearest(labels, voxels, affine, &lattice);
  ValidateLabelVolume(lattice);
  return lattice;
}

}  // namespace hapticsim
