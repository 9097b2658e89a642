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
  ExpectComplete<BlurSource>();
  ExpectComplete<RadiusUnit>();
  ExpectComplete<Side>();
  ExpectComplete<ResponseKey>();
}

TEST(Vocabulary, UnknownWordIsNotParsed) {
  EXPECT_EQ(ParseWord<Layout>("side-by-side"), std::nullopt);
  EXPECT_EQ(ParseWord<ContentType>(""), std::nullopt);
}

TEST(Vocabulary, WordsInTheParsersOrder) {
  EXPECT_EQ(Words<Counterbalance>(), (std::vector<std::string>{"swap_copies", "by_participant", "none"}));
  EXPECT_EQ(Words<Layout>(), (std::vector<std::string>{"side_by_side", "two_intervals", "single", "odd_one_out"}));
}

// Each task's traits as protocols/README.md describes the task (and the thesis's studies use it): a picture is
// matched in depth by adjustment (the pre-research study, its cut-offs stepped with previous/next and accepted, no
// deadline); a grid or ball pair is compared by forced_choice (tests 1-3: left / right / can't tell, the side showing
// more blur is correct, so procedures and criteria use it); one object is answered yes_no (Y / N) or rating.
TEST(TaskTraits, AsTheProtocolReadmeDescribesEachTask) {
  const TaskTraits& choice = TraitsOf(Task::kForcedChoice);
  EXPECT_EQ(choice.shows, TaskShows::kPair);
  EXPECT_EQ(choice.answer, TaskAnswer::kSide);
  EXPECT_TRUE(choice.scored);
  EXPECT_TRUE(choice.deadline);
  EXPECT_EQ(choice.keys, (std::vector<std::string>{"left", "right", "cant_tell"}));

  const TaskTraits& adjust = TraitsOf(Task::kAdjustment);
  EXPECT_EQ(adjust.shows, TaskShows::kPicture);
  EXPECT_EQ(adjust.answer, TaskAnswer::kLevel);
  EXPECT_FALSE(adjust.scored);
  EXPECT_FALSE(adjust.deadline);
  EXPECT_EQ(adjust.keys, (std::vector<std::string>{"previous", "next", "accept"}));

  const TaskTraits& yes_no = TraitsOf(Task::kYesNo);
  EXPECT_EQ(yes_no.shows, TaskShows::kOneObject);
  EXPECT_EQ(yes_no.answer, TaskAnswer::kYesNo);
  EXPECT_FALSE(yes_no.scored);
  EXPECT_TRUE(yes_no.deadline);
  EXPECT_EQ(yes_no.keys, (std::vector<std::string>{"yes", "no"}));

  const TaskTraits& rating = TraitsOf(Task::kRating);
  EXPECT_EQ(rating.shows, TaskShows::kOneObject);
  EXPECT_EQ(rating.answer, TaskAnswer::kRatingPoint);
  EXPECT_FALSE(rating.scored);
  EXPECT_TRUE(rating.deadline);
  EXPECT_EQ(rating.keys, (std::vector<std::string>{"rating"}));
}

// A key belongs to one task at most (so a protocol's unused key names the one task it is for), and every key a task
// lists is one the responses object accepts.
TEST(TaskTraits, EachKeyBelongsToOneTask) {
  const std::vector<std::string> accepted = {"left", "right", "cant_tell", "previous", "next", "accept",
                                             "yes",  "no",    "rating"};
  std::vector<std::string> seen;
  for (const Task task : Vocabulary<Task>::values)
    for (const std::string& key : TraitsOf(task).keys) {
      EXPECT_EQ(std::count(seen.begin(), seen.end(), key), 0) << key;
      EXPECT_EQ(std::count(accepted.begin(), accepted.end(), key), 1) << key;
      seen.push_back(key);
    }
  EXPECT_EQ(seen.size(), accepted.size());
}

TEST(TaskTraits, MessagesNameTheTasksARuleAllows) {
  EXPECT_EQ(TaskWords([](const TaskTraits& t) { return t.shows == TaskShows::kOneObject; }), "yes_no or rating");
  EXPECT_EQ(TaskWords([](const TaskTraits& t) { return t.shows == TaskShows::kPicture; }), "adjustment");
  EXPECT_EQ(TaskWords([](const TaskTraits& t) { return t.scored; }), "forced_choice");
}

}  // namespace
}  // namespace blurcue::protocol
