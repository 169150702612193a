#include "core/geometry/label_volume.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"

namespace hapticsim {
namespace {

LabelVolume Blank(int nx, int ny, int nz) {
  LabelVolume volume;
  volume.voxels = {nx, ny, nz};
  volume.spacing_m = 0.01;
  volume.origin_m = {0.1, 0.2, 0.3};
  volume.labels.assign(volume.num_voxels(), 0);
  return volume;
}

TEST(LabelVolume, CropKeepsEveryLabelledVoxelAndMovesTheOrigin) {
  LabelVolume volume = Blank(6, 5, 4);
  volume.labels[volume.Index(1, 2, 1)] = 3;
  volume.labels[volume.Index(4, 3, 2)] = 7;
  const LabelVolume cropped = CropToLabels(volume);
  EXPECT_EQ(cropped.voxels, (std::array<int, 3>{4, 2, 2}));
  EXPECT_DOUBLE_EQ(cropped.origin_m[0], 0.11);
  EXPECT_DOUBLE_EQ(cropped.origin_m[1], 0.22);
  EXPECT_DOUBLE_EQ(cropped.origin_m[2], 0.31);
  EXPECT_EQ(cropped.at(0, 0, 0), 3);
  EXPECT_EQ(cropped.at(3, 1, 1), 7);
  EXPECT_EQ(LabelsPresent(cropped), (std::vector<std::uint16_t>{3, 7}));
}

TEST(LabelVolume, AnEmptyOrMalformedVolumeIsRefusedSayingWhy) {
  EXPECT_THROW(
      {
        try {
          CropToLabels(Blank(2, 2, 2));
        } catch (const Error& error) {
          EXPECT_NE(std::string(error.what()).find("no labelled voxel"), std::string::npos);
          throw;
        }
      },
      Error);
  LabelVolume short_labels = Blank(2, 2, 2);
  short_labels.labels.pop_back();
  EXPECT_THROW(ValidateLabelVolume(short_labels), Error);
  LabelVolume nan_spacing = Blank(2, 2, 2);
  nan_spacing.spacing_m = std::nan("");
  EXPECT_THROW(ValidateLabelVolume(nan_spacing), Error);
  LabelVolume zero = Blank(2, 2, 2);
  zero.voxels[1] = 0;
  EXPECT_THROW(ValidateLabelVolume(zero), Error);
}

}  // namespace
}  // namespace hapticsim
