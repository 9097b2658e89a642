#include "protocol/vocabulary.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace blurcue::protocol {
namespace {

// Every value of E is in Vocabulary<E>::values once, and each word parses back to its value.
template <typename E>
void ExpectComplete() {
  const auto& values = Vocabulary<E>::values;
  std::vector<int> seen;
  for (const E value : values) {
    seen.push_back(static_cast<int>(value));
    EXPECT_FALSE(ToString(value).empty()) << static_cast<int>(value);
    EXPECT_EQ(ParseWord<E>(ToString(value)), value) << ToString(value);
  }
  std::sort(seen.begin(), seen.end());
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], int(i));
  // A value after the listed ones has no word: an enum value added without its place in `values` shows here.
  EXPECT_EQ(ToString(static_cast<E>(values.size())), "");
}

TEST(Vocabulary, EveryValueListedAndParsedBack) {
  ExpectComplete<Task>();
  ExpectComplete<Counterbalance>();
  ExpectComplete<ProcedureKind>();
  ExpectComplete<ProcedureVariable>();
  ExpectComplete<AdjustOrder>();
  ExpectComplete<ContentType>();
  ExpectComplete<Kernel>();
  ExpectComplete<ThresholdUnit>();
  ExpectComplete<ScenePhoto>();
  ExpectComplete<Layout>();
  ExpectComplete<BlockSequence>();
  ExpectComplete<GroupAssign>();
  ExpectComplete<InfoType>();
}

TEST(Vocabulary, UnknownWordIsNotParsed) {
  EXPECT_EQ(ParseWord<Layout>("side-by-side"), std::nullopt);
  EXPECT_EQ(ParseWord<ContentType>(""), std::nullopt);
}

TEST(Vocabulary, WordsInTheParsersOrder) {
  EXPECT_EQ(Words<Counterbalance>(), (std::vector<std::string>{"swap_copies", "by_participant", "none"}));
  EXPECT_EQ(Words<Layout>(), (std::vector<std::string>{"side_by_side", "two_intervals", "single", "odd_one_out"}));
}

}  // namespace
}  // namespace blurcue::protocol
