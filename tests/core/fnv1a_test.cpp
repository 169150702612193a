// The one FNV-1a (core/fnv1a.hpp) against the published test vectors of the 64-bit FNV-1a
// (Fowler, Noll, Vo: isthe.com/chongo/tech/comp/fnv, "FNV-1a 64" of "", "a" and "foobar"), the
// word-at-a-time way against the same arithmetic written out, and the values of the hashes built
// on it against those the copies it replaced gave.
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

// The hashes built on it kept their values through the move to one Fnv1a: a map file written
// before it loads (its sections' checksums verified), and its results checksum is the one the
// build before it computed for the same file.
TEST(Fnv1a, AMapWrittenBeforeKeepsItsChecksums) {
  const ErrorMap map = LoadErrorMap(HAPTICSIM_SMALL_MAP);
  EXPECT_EQ(map.samples.size(), 64u);
  EXPECT_EQ(map.ResultsChecksum(), 0xb1f00ec2307f9dd4ull);
}

}  // namespace
}  // namespace hapticsim
