// Fuzz target: the NIfTI label-volume reader (a .nii or .nii.gz file → LabelVolume). Anything may
// be refused with an Error; nothing may crash, hang or allocate without bound.
//
// Input layout: byte 0 picks the container, the rest is the NIfTI file's (uncompressed) content.
//  - byte 0 even: the rest is written as it is to a .nii file;
//  - byte 0 odd:  the rest is wrapped in a gzip member (stored deflate blocks, correct CRC) and
//    written to a .nii.gz file, so the mutations reach the header and data through the gzip path
//    instead of being spent on breaking the compressed stream (zlib's business, not ours).
// The file lives in /dev/shm (else the temp directory), named after the process so that parallel
// fuzzing jobs do not share it, and is removed after each input.
//
// The reader runs at spacing_m = 0 (the volume's own voxel edge). It refuses more than
// kMaxSourceVoxels output voxels itself, but that many (512 MiB of labels) is still above
// libFuzzer's -malloc_limit_mb=256, and a thin rotated volume of a few hundred bytes can
// legitimately ask for it. So inputs whose output could exceed kMaxFuzzOutputVoxels, and whose
// data could be present, are skipped: with spacing 0 each output axis has at most
// dim[1] + dim[2] + dim[3] + 2 voxels (the voxel edge is the affine's column norm). Headers
// claiming more data than the input holds still go through: the reader must refuse those before
// it allocates anything.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "core/geometry/label_volume.hpp"
#include "core/geometry/nifti_reader.hpp"

namespace {

constexpr double kMaxFuzzOutputVoxels = 1 << 22;

std::uint32_t Crc32(const std::uint8_t* data, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void AppendLittleEndian(std::string* out, std::uint32_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>(value >> (8 * i) & 0xFF));
}

/// A gzip member holding `data` uncompressed (deflate "stored" blocks of up to 65535 bytes).
std::string Gzip(const std::uint8_t* data, std::size_t size) {
  std::string out = {'\x1f', '\x8b', '\x08', '\0', '\0', '\0', '\0', '\0', '\0', '\xff'};
  std::size_t done = 0;
  do {
    const std::size_t length = std::min<std::size_t>(size - done, 65535);
    const bool last = done + length == size;
    out.push_back(last ? '\x01' : '\0');
    AppendLittleEndian(&out, static_cast<std::uint32_t>(length), 2);
    AppendLittleEndian(&out, static_cast<std::uint32_t>(~length & 0xFFFF), 2);
    out.append(reinterpret_cast<const char*>(data + done), length);
    done += length;
  } while (done < size);
  AppendLittleEndian(&out, Crc32(data, size), 4);
  AppendLittleEndian(&out, static_cast<std::uint32_t>(size), 4);
  return out;
}

template <typename Field>
Field ReadField(const std::uint8_t* data, std::size_t offset, bool swapped) {
  std::array<std::uint8_t, sizeof(Field)> bytes;
  std::memcpy(bytes.data(), data + offset, sizeof(Field));
  if (swapped) std::reverse(bytes.begin(), bytes.end());
  Field value;
  std::memcpy(&value, bytes.data(), sizeof(Field));
  return value;
}

/// True when the header (NIfTI-1 or -2, either byte order) could make the reader allocate an
/// output lattice above kMaxFuzzOutputVoxels (see the file comment).
bool OutputCouldBeTooLarge(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return false;
  const std::int32_t native = ReadField<std::int32_t>(data, 0, false);
  const std::int32_t swapped_size = ReadField<std::int32_t>(data, 0, true);
  const bool swapped = native != 348 && native != 540;
  const std::int32_t header_size = swapped ? swapped_size : native;
  const bool nifti2 = header_size == 540;
  if ((header_size != 348 && !nifti2) || size < static_cast<std::size_t>(header_size)) {
    return false;  // the reader refuses it before looking at the dims
  }
  double sum = 0, product = 1;
  for (int axis = 1; axis <= 3; ++axis) {
    const double dim =
        nifti2 ? static_cast<double>(ReadField<std::int64_t>(data, 16 + 8 * axis, swapped))
               : static_cast<double>(ReadField<std::int16_t>(data, 40 + 2 * axis, swapped));
    sum += std::max(dim, 0.0);
    product *= std::max(dim, 0.0);
  }
  const double per_axis = sum * (1 + 1e-5) + 2;
  const bool data_could_be_present = product <= static_cast<double>(size);
  return data_could_be_present && per_axis * per_axis * per_axis > kMaxFuzzOutputVoxels;
}

std::filesystem::path FuzzFile(bool gzipped) {
  std::error_code error;
  const std::filesystem::path dir = std::filesystem::is_directory("/dev/shm", error)
                                        ? std::filesystem::path("/dev/shm")
                                        : std::filesystem::temp_directory_path();
  const std::string stem = "hapticsim-nifti-fuzz-" + std::to_string(::getpid());
  // Different stems: libnifti2 looks for x.nii before x.nii.gz.
  return dir / (gzipped ? stem + "-gz.nii.gz" : stem + ".nii");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool gzipped = (data[0] & 1) != 0;
  const std::uint8_t* content = data + 1;
  const std::size_t content_size = size - 1;
  if (OutputCouldBeTooLarge(content, content_size)) return 0;

  const std::filesystem::path path = FuzzFile(gzipped);
  {
    const std::string bytes =
        gzipped ? Gzip(content, content_size)
                : std::string(reinterpret_cast<const char*>(content), content_size);
    std::ofstream(path, std::ios::binary).write(bytes.data(), bytes.size());
  }
  try {
    const hapticsim::LabelVolume volume = hapticsim::ReadNiftiLabels(path.string(), 0);
    hapticsim::ValidateLabelVolume(volume);  // what is returned must be a valid volume
  } catch (const hapticsim::Error&) {
  }
  std::error_code error;
  std::filesystem::remove(path, error);
  return 0;
}
