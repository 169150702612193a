// The one FNV-1a (core/fnv1a.hpp) against the published test vectors of the 64-bit FNV-1a
// (Fowler, Noll, Vo: isthe.com/chongo/tech/comp/fnv, "FNV-1a 64" of "", "a" and "foobar"), the
// word-at-a-time way against the same arithmetic written out, and a map's results checksum against
// the byte-at-a-time loop written out.
#include "core/fnv1a.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "core/errormap/error_map.hpp"
#include "core/errormap/error_map_file.hpp"

namespace hapticsim {
namespace {

std::uint64_t OfBytes(const std::string& text) {
  Fnv1a hash;
  hash.Bytes(text.data(), text.size());
  return hash.value();
}

TEST(Fnv1a, BytesGiveThePublishedValues) {
  EXPECT_EQ(OfBytes(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(OfBytes("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(OfBytes("foobar"), 0x85944171f73967e8ull);
}

TEST(Fnv1a, AWordIsOneStepOfTheSameArithmetic) {
  Fnv1a hash;
  hash.Word(0x0123456789abcdefull);
  EXPECT_EQ(hash.value(), (0xcbf29ce484222325ull ^ 0x0123456789abcdefull) * 0x100000001b3ull);
  // A single byte as a word is the byte-wise hash of that byte: the two ways agree there only.
  Fnv1a word, byte;
  word.Word('a');
  byte.Bytes("a", 1);
  EXPECT_EQ(word.value(), byte.value());
}

// The map's results checksum is FNV-1a over each sample's bytes: the committed map (its sections'
// checksums verified on load) gives the value of the textbook byte-at-a-time loop written here,
// and the value it gave when it was written.
TEST(Fnv1a, AMapsResultsChecksumIsTheTextbookHashOfItsSamples) {
  const ErrorMap map = LoadErrorMap(HAPTICSIM_SMALL_MAP);
  EXPECT_EQ(map.samples.size(), 64u);
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&h](const void* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) {
      h ^= static_cast<const unsigned char*>(data)[i];
      h *= 0x100000001b3ull;
    }
  };
  for (const MapSample& s : map.samples) {
    mix(s.point.data(), sizeof s.point);
    for (double v : {s.l2_percent, s.max_magnitude_percent, s.max_direction_deg, s.reference_peak_n,
                     s.spectral_radius}) {
      mix(&v, sizeof v);
    }
    mix(&s.status, sizeof s.status);
    mix(&s.status_region, sizeof s.status_region);
  }
  EXPECT_EQ(map.ResultsChecksum(), h);
  // And pinned, so that a change to what a map's samples hold is seen: this is the value of the
  // map fuzz/make_seeds.cpp wrote in format 3.
  EXPECT_EQ(h, 0x33370c53b4b0824ull);
}

}  // namespace
}  // namespace hapticsim
