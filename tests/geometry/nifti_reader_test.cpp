#include "core/geometry/nifti_reader.hpp"

#include <gtest/gtest.h>
#include <nifti1.h>
#include <nifti2.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"

// The NIfTI files are written here byte by byte from the header structs of the format's own
// definition (nifti1.h, nifti2.h), not through libnifti2, so the reader's use of the library is
// checked against files it did not make.

namespace hapticsim {
namespace {

using Dims = std::array<int, 3>;

/// A NIfTI-1 header for a 3-D volume with no orientation but its pixdims (qform_code and
/// sform_code 0), millimetres, data right after the header and its 4-byte extension flag.
nifti_1_header MakeHeader(const Dims& voxels, short datatype, short bitpix,
                          const std::array<float, 3>& pixdim_mm) {
  nifti_1_header header;
  std::memset(&header, 0, sizeof(header));
  header.sizeof_hdr = sizeof(nifti_1_header);
  header.dim[0] = 3;
  for (int axis = 0; axis < 3; ++axis) {
    header.dim[axis + 1] = static_cast<short>(voxels[axis]);
    header.pixdim[axis + 1] = pixdim_mm[axis];
  }
  for (int axis = 4; axis < 8; ++axis) header.dim[axis] = 1;
  header.pixdim[0] = 1;  // qfac
  header.datatype = datatype;
  header.bitpix = bitpix;
  header.vox_offset = 352;
  header.xyzt_units = NIFTI_UNITS_MM;
  std::memcpy(header.magic, "n+1", 4);
  return header;
}

/// The same volume as a NIfTI-2 header.
nifti_2_header MakeHeader2(const Dims& voxels, short datatype, short bitpix, double pixdim_mm) {
  nifti_2_header header;
  std::memset(&header, 0, sizeof(header));
  header.sizeof_hdr = sizeof(nifti_2_header);
  std::memcpy(header.magic, "n+2\0\r\n\032\n", 8);
  header.datatype = datatype;
  header.bitpix = bitpix;
  header.dim[0] = 3;
  for (int axis = 0; axis < 3; ++axis) {
    header.dim[axis + 1] = voxels[axis];
    header.pixdim[axis + 1] = pixdim_mm;
  }
  for (int axis = 4; axis < 8; ++axis) header.dim[axis] = 1;
  header.pixdim[0] = 1;
  header.vox_offset = sizeof(nifti_2_header) + 4;
  header.xyzt_units = NIFTI_UNITS_MM;
  return header;
}

/// An identity qform: voxel (i, j, k)'s centre at offset + pixdim·(i, j, k).
void SetIdentityQform(nifti_1_header* header, const std::array<float, 3>& offset_mm) {
  header->qform_code = NIFTI_XFORM_SCANNER_ANAT;
  header->quatern_b = header->quatern_c = header->quatern_d = 0;
  header->qoffset_x = offset_mm[0];
  header->qoffset_y = offset_mm[1];
  header->qoffset_z = offset_mm[2];
}

template <typename Value>
std::vector<char> Bytes(const std::vector<Value>& values) {
  std::vector<char> bytes(values.size() * sizeof(Value));
  std::memcpy(bytes.data(), values.data(), bytes.size());
  return bytes;
}

/// One value per voxel, x fastest, from label(x, y, z).
template <typename Value>
std::vector<Value> Fill(const Dims& voxels, const std::function<int(int, int, int)>& label) {
  std::vector<Value> values;
  for (int z = 0; z < voxels[2]; ++z) {
    for (int y = 0; y < voxels[1]; ++y) {
      for (int x = 0; x < voxels[0]; ++x) values.push_back(static_cast<Value>(label(x, y, z)));
    }
  }
  return values;
}

/// Header, the 4-byte extension flag (none), data: a single-file NIfTI.
std::string FileBytes(const void* header, std::size_t header_size, const std::vector<char>& data) {
  std::string bytes(static_cast<const char*>(header), header_size);
  bytes.append(4, '\0');
  bytes.append(data.begin(), data.end());
  return bytes;
}

class NiftiReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("hapticsim_nifti_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& bytes) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary).write(bytes.data(), bytes.size());
    return path;
  }
  std::string WriteGz(const std::string& name, const std::string& bytes) {
    const std::string path = (dir_ / name).string();
    gzFile file = gzopen(path.c_str(), "wb");
    EXPECT_NE(file, nullptr);
    EXPECT_EQ(gzwrite(file, bytes.data(), static_cast<unsigned>(bytes.size())),
              static_cast<int>(bytes.size()));
    gzclose(file);
    return path;
  }
  std::string Write(const std::string& name, const nifti_1_header& header,
                    const std::vector<char>& data) {
    return Write(name, FileBytes(&header, sizeof(header), data));
  }

  /// The message of the Error reading `path` throws ("" when it reads).
  static std::string ErrorOf(const std::string& path, double spacing_m = 0) {
    try {
      ReadNiftiLabels(path, spacing_m);
    } catch (const Error& error) {
      return error.what();
    }
    return "";
  }

  std::filesystem::path dir_;
};

#define EXPECT_ERROR_SAYS(message, phrase)                        \
  EXPECT_NE(std::string(message).find(phrase), std::string::npos) \
      << "expected an error saying \"" << (phrase) << "\", got \"" << (message) << "\""

const Dims kSmall = {4, 3, 2};
int SmallLabel(int x, int y, int z) { return (x + 2 * y + z) % 3; }  // labels 0, 1, 2

void ExpectSmallVolume(const LabelVolume& volume) {
  ASSERT_EQ(volume.voxels, kSmall);
  EXPECT_DOUBLE_EQ(volume.spacing_m, 0.002);
  // The qform puts voxel (0, 0, 0)'s centre at (10, 20, 30) mm: its lowest corner is 1 mm less.
  EXPECT_NEAR(volume.origin_m[0], 0.009, 1e-12);
  EXPECT_NEAR(volume.origin_m[1], 0.019, 1e-12);
  EXPECT_NEAR(volume.origin_m[2], 0.029, 1e-12);
  for (int z = 0; z < 2; ++z) {
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 4; ++x) {
        EXPECT_EQ(volume.at(x, y, z), SmallLabel(x, y, z)) << x << "," << y << "," << z;
      }
    }
  }
}

TEST_F(NiftiReaderTest, ReadsASmallUint8AndInt16VolumeLabelForLabel) {
  nifti_1_header bytes8 = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  SetIdentityQform(&bytes8, {10, 20, 30});
  ExpectSmallVolume(ReadNiftiLabels(
      Write("small8.nii", bytes8, Bytes(Fill<std::uint8_t>(kSmall, SmallLabel))), 0));

  nifti_1_header bytes16 = MakeHeader(kSmall, DT_INT16, 16, {2, 2, 2});
  SetIdentityQform(&bytes16, {10, 20, 30});
  const std::vector<char> data16 = Bytes(Fill<std::int16_t>(kSmall, SmallLabel));
  ExpectSmallVolume(ReadNiftiLabels(Write("small16.nii", bytes16, data16), 0));
  // Asking for the volume's own spacing explicitly changes nothing.
  ExpectSmallVolume(ReadNiftiLabels(Write("small16b.nii", bytes16, data16), 0.002));
}

TEST_F(NiftiReaderTest, ReadsAGzippedVolume) {
  nifti_1_header header = MakeHeader(kSmall, DT_INT16, 16, {2, 2, 2});
  SetIdentityQform(&header, {10, 20, 30});
  const std::string bytes =
      FileBytes(&header, sizeof(header), Bytes(Fill<std::int16_t>(kSmall, SmallLabel)));
  ExpectSmallVolume(ReadNiftiLabels(WriteGz("small.nii.gz", bytes), 0));
}

TEST_F(NiftiReaderTest, ReadsANifti2Volume) {
  nifti_2_header header = MakeHeader2(kSmall, DT_UINT16, 16, 2.0);
  header.qform_code = NIFTI_XFORM_SCANNER_ANAT;
  header.qoffset_x = 10;
  header.qoffset_y = 20;
  header.qoffset_z = 30;
  const std::string bytes =
      FileBytes(&header, sizeof(header), Bytes(Fill<std::uint16_t>(kSmall, SmallLabel)));
  ExpectSmallVolume(ReadNiftiLabels(Write("small2.nii", bytes), 0));
}

template <typename Field>
void Swap(Field* field) {
  auto* bytes = reinterpret_cast<unsigned char*>(field);
  std::reverse(bytes, bytes + sizeof(Field));
}

TEST_F(NiftiReaderTest, ReadsAHeaderAndDataOfTheOtherByteOrder) {
  nifti_1_header header = MakeHeader(kSmall, DT_INT16, 16, {2, 2, 2});
  SetIdentityQform(&header, {10, 20, 30});
  Swap(&header.sizeof_hdr);
  for (short& dim : header.dim) Swap(&dim);
  for (float& pixdim : header.pixdim) Swap(&pixdim);
  Swap(&header.datatype);
  Swap(&header.bitpix);
  Swap(&header.vox_offset);
  Swap(&header.qform_code);
  for (float* value : {&header.qoffset_x, &header.qoffset_y, &header.qoffset_z}) Swap(value);
  std::vector<std::int16_t> values = Fill<std::int16_t>(kSmall, SmallLabel);
  for (std::int16_t& value : values) Swap(&value);
  ExpectSmallVolume(ReadNiftiLabels(Write("swapped.nii", header, Bytes(values)), 0));
}

TEST_F(NiftiReaderTest, ConvertsMetresMillimetresAndMicronsToMetres) {
  const std::vector<char> data = Bytes(Fill<std::uint8_t>(kSmall, SmallLabel));
  const std::map<int, double> metres_per_unit = {{NIFTI_UNITS_METER, 1.0},
                                                 {NIFTI_UNITS_MM, 1e-3},
                                                 {NIFTI_UNITS_MICRON, 1e-6},
                                                 {NIFTI_UNITS_UNKNOWN, 1e-3}};  // the default
  for (const auto& [units, scale] : metres_per_unit) {
    nifti_1_header header = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
    SetIdentityQform(&header, {10, 20, 30});
    header.xyzt_units = static_cast<char>(units | NIFTI_UNITS_SEC);  // time units do not matter
    const LabelVolume volume =
        ReadNiftiLabels(Write("units" + std::to_string(units) + ".nii", header, data), 0);
    EXPECT_DOUBLE_EQ(volume.spacing_m, 2 * scale) << "units " << units;
    EXPECT_NEAR(volume.origin_m[0], 9 * scale, 1e-12 * scale) << "units " << units;
    EXPECT_NEAR(volume.origin_m[2], 29 * scale, 1e-12 * scale) << "units " << units;
    EXPECT_EQ(volume.labels.size(), 24u);
  }
}

TEST_F(NiftiReaderTest, AFlippedAndPermutedSformReordersTheLabelsExactly) {
  // World x = -2k + 4, world y = 2i, world z = 2j - 6 (mm): i runs along y, j along z, and k
  // backwards along x. Every voxel gets its own label so a misplaced one shows.
  nifti_1_header header = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  SetIdentityQform(&header, {100, 100, 100});  // set but overridden: the sform comes first
  header.sform_code = NIFTI_XFORM_ALIGNED_ANAT;
  const float srow_x[4] = {0, 0, -2, 4}, srow_y[4] = {2, 0, 0, 0}, srow_z[4] = {0, 2, 0, -6};
  std::memcpy(header.srow_x, srow_x, sizeof(srow_x));
  std::memcpy(header.srow_y, srow_y, sizeof(srow_y));
  std::memcpy(header.srow_z, srow_z, sizeof(srow_z));
  const auto label = [](int i, int j, int k) { return 1 + i + 4 * j + 12 * k; };
  const LabelVolume volume =
      ReadNiftiLabels(Write("permuted.nii", header, Bytes(Fill<std::uint8_t>(kSmall, label))), 0);

  // x spans k = 1..0 → centres 2..4 mm → box 1..5 mm; y: i = 0..3 → -1..7 mm; z: j → -7..-1.
  ASSERT_EQ(volume.voxels, (Dims{2, 4, 3}));
  EXPECT_DOUBLE_EQ(volume.spacing_m, 0.002);
  EXPECT_NEAR(volume.origin_m[0], 0.001, 1e-12);
  EXPECT_NEAR(volume.origin_m[1], -0.001, 1e-12);
  EXPECT_NEAR(volume.origin_m[2], -0.007, 1e-12);
  for (int z = 0; z < 3; ++z) {
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 2; ++x) {
        // Output x = 0 is the lowest world x, the highest k.
        EXPECT_EQ(volume.at(x, y, z), label(y, z, 1 - x)) << x << "," << y << "," << z;
      }
    }
  }
}

TEST_F(NiftiReaderTest, AnisotropicVoxelsNeedASpacingAndAreThenResampled) {
  const nifti_1_header header = MakeHeader(kSmall, DT_UINT8, 8, {1, 1, 2});
  const auto label = [](int x, int y, int z) { return 1 + x + 4 * y + 12 * z; };
  const std::string path =
      Write("anisotropic.nii", header, Bytes(Fill<std::uint8_t>(kSmall, label)));
  const std::string message = ErrorOf(path, 0);
  EXPECT_ERROR_SAYS(message, "1 x 1 x 2 mm");
  EXPECT_ERROR_SAYS(message, "geometry.spacing_m");

  const LabelVolume volume = ReadNiftiLabels(path, 0.001);
  ASSERT_EQ(volume.voxels, (Dims{4, 3, 4}));
  EXPECT_DOUBLE_EQ(volume.spacing_m, 0.001);
  EXPECT_NEAR(volume.origin_m[2], -0.001, 1e-12);  // pixdim only: voxel centres at 2k mm
  for (int z = 0; z < 4; ++z) {
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 4; ++x) {
        EXPECT_EQ(volume.at(x, y, z), label(x, y, z / 2)) << x << "," << y << "," << z;
      }
    }
  }
}

TEST_F(NiftiReaderTest, ACoarserSpacingPicksTheNearestLabels) {
  // 6 x 6 x 6 voxels of 1 mm in eight 3 x 3 x 3 blocks, labelled 1..8, and one voxel 9 at the
  // centre of block 1. At 3 mm each output centre falls on a block's centre voxel.
  const Dims voxels = {6, 6, 6};
  const auto label = [](int x, int y, int z) {
    if (x == 1 && y == 1 && z == 1) return 9;
    return 1 + x / 3 + 2 * (y / 3) + 4 * (z / 3);
  };
  const nifti_1_header header = MakeHeader(voxels, DT_UINT8, 8, {1, 1, 1});
  const LabelVolume volume =
      ReadNiftiLabels(Write("blocks.nii", header, Bytes(Fill<std::uint8_t>(voxels, label))), 0.003);
  ASSERT_EQ(volume.voxels, (Dims{2, 2, 2}));
  std::map<int, int> counts;
  for (std::uint16_t value : volume.labels) ++counts[value];
  EXPECT_EQ(counts,
            (std::map<int, int>{{2, 1}, {3, 1}, {4, 1}, {5, 1}, {6, 1}, {7, 1}, {8, 1}, {9, 1}}));
  EXPECT_EQ(volume.at(0, 0, 0), 9);
  EXPECT_EQ(volume.at(1, 1, 1), 8);

  // At 2 mm each output centre lies exactly between source centres: it takes the higher index.
  // The 4 x 4 x 4 volume labelled by the parity of its indices becomes all odd-odd-odd (8).
  const Dims four = {4, 4, 4};
  const auto parity = [](int x, int y, int z) { return 1 + x % 2 + 2 * (y % 2) + 4 * (z % 2); };
  const LabelVolume halved =
      ReadNiftiLabels(Write("parity.nii", MakeHeader(four, DT_UINT8, 8, {1, 1, 1}),
                            Bytes(Fill<std::uint8_t>(four, parity))),
                      0.002);
  ASSERT_EQ(halved.voxels, (Dims{2, 2, 2}));
  EXPECT_EQ(halved.labels, std::vector<std::uint16_t>(8, 8));
}

TEST_F(NiftiReaderTest, FloatLabelsAreReadWhenWhole) {
  nifti_1_header header = MakeHeader(kSmall, DT_FLOAT32, 32, {2, 2, 2});
  SetIdentityQform(&header, {10, 20, 30});
  ExpectSmallVolume(
      ReadNiftiLabels(Write("float.nii", header, Bytes(Fill<float>(kSmall, SmallLabel))), 0));
}

// ---- bad input: each refused with an Error that says what is wrong ----

TEST_F(NiftiReaderTest, RefusesTruncatedData) {
  const nifti_1_header header = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  std::vector<char> data = Bytes(Fill<std::uint8_t>(kSmall, SmallLabel));
  data.resize(10);
  // Both found short before the data is read (libnifti2 would first allocate what is claimed).
  const std::string message = ErrorOf(Write("truncated.nii", header, data));
  EXPECT_ERROR_SAYS(message, "truncated");
  EXPECT_ERROR_SAYS(message, "declares 24 bytes of voxel data from byte 352, but it is 362 bytes");
  const std::string gz_message =
      ErrorOf(WriteGz("truncated_gz.nii.gz", FileBytes(&header, sizeof(header), data)));
  EXPECT_ERROR_SAYS(gz_message, "truncated");
  EXPECT_ERROR_SAYS(gz_message, "does not hold the 24 bytes");
}

TEST_F(NiftiReaderTest, RefusesATruncatedHeaderAMissingFileAndGarbage) {
  const nifti_1_header header = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  const std::string hundred_bytes(reinterpret_cast<const char*>(&header), 100);
  EXPECT_ERROR_SAYS(ErrorOf(Write("short.nii", hundred_bytes)), "shorter than the 348-byte");
  EXPECT_ERROR_SAYS(ErrorOf(WriteGz("short.nii.gz", hundred_bytes)), "cannot read a NIfTI header");
  const nifti_2_header header2 = MakeHeader2(kSmall, DT_UINT8, 8, 2.0);
  EXPECT_ERROR_SAYS(
      ErrorOf(Write("short2.nii", std::string(reinterpret_cast<const char*>(&header2), 400))),
      "shorter than the 540-byte");
  EXPECT_ERROR_SAYS(ErrorOf((dir_ / "missing.nii").string()), "no such file");
  EXPECT_ERROR_SAYS(ErrorOf((dir_ / "missing.nii.gz").string()), "no such file");
  EXPECT_ERROR_SAYS(ErrorOf(Write("volume.txt", FileBytes(&header, sizeof(header), {}))),
                    ".nii or .nii.gz");

  std::mt19937 random(20240601);
  std::string garbage(1000, '\0');
  for (char& byte : garbage) byte = static_cast<char>(random());
  EXPECT_ERROR_SAYS(ErrorOf(Write("garbage.nii", garbage)), "not a NIfTI");
  EXPECT_ERROR_SAYS(ErrorOf(Write("ascii.nii", "<nifti_image" + garbage)), "ASCII");
}

TEST_F(NiftiReaderTest, RefusesAGzipClaimingDataItDoesNotHold) {
  // 2^28 voxels claimed by a few dozen bytes: refused without allocating the claimed 256 MiB.
  const nifti_1_header header = MakeHeader({16384, 16384, 1}, DT_UINT8, 8, {1, 1, 1});
  EXPECT_ERROR_SAYS(ErrorOf(WriteGz("claim.nii.gz", FileBytes(&header, sizeof(header), {}))),
                    "does not hold the 268435456 bytes");
}

TEST_F(NiftiReaderTest, RefusesAGzipWhoseUncompressedTwinLibniftiWouldRead) {
  const nifti_1_header header = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  const std::string bytes =
      FileBytes(&header, sizeof(header), Bytes(Fill<std::uint8_t>(kSmall, SmallLabel)));
  const std::string gz = WriteGz("twin.nii.gz", bytes);
  Write("twin.nii", bytes);
  EXPECT_ERROR_SAYS(ErrorOf(gz), "would read the voxel data from");
}

TEST_F(NiftiReaderTest, RefusesVolumesThatAreNot3D) {
  const std::vector<char> data = Bytes(Fill<std::uint8_t>(kSmall, SmallLabel));
  nifti_1_header flat = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  flat.dim[0] = 2;
  EXPECT_ERROR_SAYS(ErrorOf(Write("flat.nii", flat, data)), "2-D volume");
  nifti_1_header five = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  five.dim[0] = 5;
  five.dim[5] = 2;
  EXPECT_ERROR_SAYS(ErrorOf(Write("five.nii", five, data)), "5-D volume");
  nifti_1_header series = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  series.dim[0] = 4;
  series.dim[4] = 2;
  EXPECT_ERROR_SAYS(ErrorOf(Write("series.nii", series, data)), "4-D volume");
  nifti_1_header one_time_point = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  one_time_point.dim[0] = 4;
  EXPECT_EQ(ReadNiftiLabels(Write("one_time_point.nii", one_time_point, data), 0).labels.size(),
            24u);
  nifti_1_header empty = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  empty.dim[2] = 0;
  EXPECT_ERROR_SAYS(ErrorOf(Write("empty.nii", empty, data)), "dim[2] is 0");
}

TEST_F(NiftiReaderTest, RefusesNanAndNegativeVoxelSizes) {
  const std::vector<char> data = Bytes(Fill<std::uint8_t>(kSmall, SmallLabel));
  const nifti_1_header nan_size =
      MakeHeader(kSmall, DT_UINT8, 8, {std::numeric_limits<float>::quiet_NaN(), 2, 2});
  EXPECT_ERROR_SAYS(ErrorOf(Write("nan.nii", nan_size, data)), "pixdim[1] is nan");
  const nifti_1_header negative = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, -2});
  EXPECT_ERROR_SAYS(ErrorOf(Write("negative.nii", negative, data)), "pixdim[3] is -2");
}

TEST_F(NiftiReaderTest, RefusesValuesThatAreNotLabels) {
  std::vector<float> floats = Fill<float>(kSmall, SmallLabel);
  floats[5] = 1.5f;
  EXPECT_ERROR_SAYS(
      ErrorOf(Write("half.nii", MakeHeader(kSmall, DT_FLOAT32, 32, {2, 2, 2}), Bytes(floats))),
      "holds 1.5");
  std::vector<std::int16_t> shorts = Fill<std::int16_t>(kSmall, SmallLabel);
  shorts[1 + 4 * 2] = -3;  // voxel (1, 2, 0)
  const std::string message = ErrorOf(
      Write("negative_label.nii", MakeHeader(kSmall, DT_INT16, 16, {2, 2, 2}), Bytes(shorts)));
  EXPECT_ERROR_SAYS(message, "voxel (1, 2, 0) holds -3");
  std::vector<std::int32_t> ints = Fill<std::int32_t>(kSmall, SmallLabel);
  ints[23] = 70000;
  EXPECT_ERROR_SAYS(
      ErrorOf(Write("large_label.nii", MakeHeader(kSmall, DT_INT32, 32, {2, 2, 2}), Bytes(ints))),
      "voxel (3, 2, 1) holds 70000");
  EXPECT_ERROR_SAYS(ErrorOf(Write("rgb.nii", MakeHeader(kSmall, DT_RGB24, 24, {2, 2, 2}),
                                  std::vector<char>(72, 0))),
                    "cannot be labels");
}

TEST_F(NiftiReaderTest, RefusesScaledData) {
  nifti_1_header header = MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2});
  header.scl_slope = 2;
  EXPECT_ERROR_SAYS(
      ErrorOf(Write("scaled.nii", header, Bytes(Fill<std::uint8_t>(kSmall, SmallLabel)))),
      "scaled");
  header.scl_slope = 1;  // the identity scaling is no scaling
  EXPECT_EQ(ReadNiftiLabels(
                Write("unscaled.nii", header, Bytes(Fill<std::uint8_t>(kSmall, SmallLabel))), 0)
                .labels.size(),
            24u);
}

TEST_F(NiftiReaderTest, RefusesTooManyVoxelsFromTheHeaderAlone) {
  // Header only: the claim is refused before any data is looked for.
  nifti_1_header big = MakeHeader({32767, 32767, 32767}, DT_UINT8, 8, {1, 1, 1});
  EXPECT_ERROR_SAYS(ErrorOf(Write("big.nii", big, {})), "more than the 268435456");
  // 2^40 per axis: the product of the NIfTI-2 dims would overflow 64 bits.
  nifti_2_header huge = MakeHeader2({1, 1, 1}, DT_UINT8, 8, 1.0);
  huge.dim[1] = huge.dim[2] = huge.dim[3] = std::int64_t{1} << 40;
  EXPECT_ERROR_SAYS(ErrorOf(Write("huge.nii", FileBytes(&huge, sizeof(huge), {}))),
                    "more than the 268435456");
  huge.dim[1] = huge.dim[2] = huge.dim[3] = std::int64_t{1} << 21;  // 2^63: overflows too
  EXPECT_ERROR_SAYS(ErrorOf(Write("huge2.nii", FileBytes(&huge, sizeof(huge), {}))),
                    "more than the 268435456");
  // A valid volume at a spacing far too fine for its size.
  const std::string fine = Write("fine.nii", MakeHeader(kSmall, DT_UINT8, 8, {2, 2, 2}),
                                 Bytes(Fill<std::uint8_t>(kSmall, SmallLabel)));
  EXPECT_ERROR_SAYS(ErrorOf(fine, 1e-6), "coarser geometry.spacing_m");
  EXPECT_ERROR_SAYS(ErrorOf(fine, -1), "must be finite");
}

}  // namespace
}  // namespace hapticsim
