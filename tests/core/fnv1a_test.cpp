// The one FNV-1a (core/fnv1a.hpp) against the published test vectors of the 64-bit FNV-1a
// (Fowler, Noll, Vo: isthe.com/chongo/tech/comp/fnv, "FNV-1a 64" of "", "a" and "foobar"), and
// the word-at-a-time way against the same arithmetic written out.
#include "core/fnv1a.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

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

}  // namespace
}  // namespace hapticsim
