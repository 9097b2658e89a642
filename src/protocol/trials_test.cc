#include "protocol/trials.h"
#include "core/typed.h"
#include "blurcue/source_dir.h"

#include <map>
#include <set>

#include <gtest/gtest.h>

#include <algorithm>

#include "core/error.h"

namespace blurcue::protocol {
namespace {

namespace fs = std::filesystem;

Protocol Shipped(const char* name) {
  return LoadProtocol(fs::path(BLURCUE_SOURCE_DIR) / "protocols" / name, ValidateOptions{false});
}

Protocol FromJson(const std::string& text) { return ParseProtocol(Json::parse(text), "inline.json", {false}); }

// Four trials whose order is the only randomness: levels 0..3 of one factor.
const char* kFour = R"({
  "name": "four", "version": 1,
  "scene": {"background": "s.png", "calib": "c.json"}, "content": {"type": "grid"},
  "task": "forced_choice", "sides": {"left": "measured", "right": "estimated"},
  "factors": {"edge": [1, 2, 3, 4]}
})";

std::vector<int> Edges(const std::vector<Trial>& trials) {
  std::vector<int> edges;
  for (const auto& t : trials) edges.push_back(ToJson(t.levels)["edge"].get<int>());
  return edges;
}

// A participant id is what the record, the tables and the report hold as one line: any script, but no newline,
// escape or broken bytes, no space at either end, at most 64 bytes; refused with the id shown on one line.
TEST(TrialBuilder, ParticipantIdsAreOnePrintableLine) {
  const Protocol p = FromJson(kFour);
  for (const char* id : {"P1", "S-01_b", "Zoë 3", "参加者7", "x"}) EXPECT_EQ(BuildTrials(p, id, 1).size(), 4u) << id;
  EXPECT_NO_THROW(BuildTrials(p, std::string(kMaxParticipantIdBytes, 'a'), 1));
  const std::pair<std::string, std::string> bad[] = {
      {"", "must not be empty"},
      {std::string(100000, 'a'), "must be at most 64 bytes (it has 100000)"},
      {"P\n1", "must be printable UTF-8"},
      {"P\t1", "must be printable UTF-8"},
      {"\x1b[2JP1", "must be printable UTF-8"},
      {"P\xff", "must be printable UTF-8"},
      {" P1", "must not begin or end with a space"},
      {"P1 ", "must not begin or end with a space"},
  };
  for (const auto& [id, why] : bad) {
    try {
      BuildTrials(p, id, 1);
      ADD_FAILURE() << "accepted " << id.substr(0, 20);
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_EQ(e.kind(), ErrorKind::kUsage);
      EXPECT_NE(message.find("--participant " + why), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_LT(message.size(), 200u) << message;
    }
  }
}

// A procedure block: procedure.trials copies of each crossing, the reference on both sides, a seeded test side
// per trial, shuffled together so the crossings' procedures interleave.
TEST(TrialBuilder, ProcedureBlocksInterleaveTheirCrossingsWithSeededTestSides) {
  const Protocol p = FromJson(R"({
    "name": "adaptive", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
    "content": {"type": "grid"}, "task": "forced_choice",
    "factors": {"edge": [4, 8]},
    "blocks": [{"name": "stairs", "procedure": {"type": "staircase", "variable": "difference_arcmin",
                "reference": "measured", "trials": 25, "start": 2, "min": 0, "max": 6, "steps": [1, 0.5]}}]
  })");
  const auto a = BuildTrials(p, "P1", 42), b = BuildTrials(p, "P1", 42), c = BuildTrials(p, "P1", 43);
  ASSERT_EQ(a.size(), 50u);
  EXPECT_EQ(TrialsHash(a), TrialsHash(b));
  EXPECT_NE(TrialsHash(a), TrialsHash(c));
  int per_cell[2] = {0, 0}, left = 0, switches = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const Trial& t = a[i];
    ASSERT_TRUE(t.cell == 0 || t.cell == 1);
    ++per_cell[t.cell];
    EXPECT_EQ(ToJson(t.levels)["edge"], t.cell == 0 ? 4 : 8);
    EXPECT_EQ(ToJson(t.left), "measured");
    EXPECT_EQ(ToJson(t.right), "measured");
    ASSERT_TRUE(t.test_side == "left" || t.test_side == "right");
    left += t.test_side == "left";
    if (i > 0 && a[i - 1].cell != t.cell) ++switches;
  }
  EXPECT_EQ(per_cell[0], 25);
  EXPECT_EQ(per_cell[1], 25);
  EXPECT_GT(left, 12);  // about half, drawn with the seed
  EXPECT_LT(left, 38);
  EXPECT_GT(switches, 10);  // interleaved, not one crossing after the other
  EXPECT_EQ(ToJson(a[0])["test_side"], a[0].test_side);
}

// Odd one out: every forced-choice trial's odd interval ("1".."n") drawn with the seed, about equally often each.
TEST(TrialBuilder, OddOneOutDrawsEachTrialsOddInterval) {
  const Protocol p = FromJson(R"({
    "name": "odd", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
    "content": {"type": "grid"}, "task": "forced_choice", "layout": "odd_one_out", "alternatives": 4,
    "sides": {"left": "measured", "right": "none"}, "factors": {"edge": [2, 5, 8]}, "repetitions": 40
  })");
  const auto a = BuildTrials(p, "P1", 42), b = BuildTrials(p, "P1", 42), c = BuildTrials(p, "P1", 43);
  ASSERT_EQ(a.size(), 120u);
  EXPECT_EQ(TrialsHash(a), TrialsHash(b));
  EXPECT_NE(TrialsHash(a), TrialsHash(c));
  int count[5] = {0, 0, 0, 0, 0};
  for (const Trial& t : a) {
    ASSERT_TRUE(t.test_side == "1" || t.test_side == "2" || t.test_side == "3" || t.test_side == "4") << t.test_side;
    ++count[std::stoi(t.test_side)];
    EXPECT_EQ(ToJson(t.left), "measured");
    EXPECT_EQ(ToJson(t.right), "none");
  }
  for (int k = 1; k <= 4; ++k) {
    EXPECT_GT(count[k], 15) << k;  // 30 expected
    EXPECT_LT(count[k], 45) << k;
  }
}

// The single layout's "object" is shown as the left side and recorded on both.
TEST(TrialBuilder, SingleLayoutShowsItsObject) {
  const Protocol p = FromJson(R"({
    "name": "one", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
    "content": {"type": "grid"}, "task": "yes_no", "layout": "single",
    "factors": {"edge": [2, 5], "blur": [{"object": "measured"}, {"object": 3}]}
  })");
  const auto trials = BuildTrials(p, "P1", 1);
  ASSERT_EQ(trials.size(), 4u);
  for (const Trial& t : trials) {
    EXPECT_EQ(ToJson(t.left), ToJson(t.levels)["blur"]["object"]);
    EXPECT_EQ(t.right, t.left);
    EXPECT_EQ(t.task, Task::kYesNo);
    EXPECT_TRUE(t.test_side.empty());
  }
}

// A practice block run until a criterion: its design max_repeats times, each run its own shuffle, numbered.
TEST(TrialBuilder, PracticeToACriterionRunsItsDesignInRounds) {
  const Protocol p = FromJson(R"({
    "name": "rounds", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
    "content": {"type": "grid"}, "task": "forced_choice", "sides": {"left": "measured", "right": "none"},
    "blocks": [{"name": "warmup", "practice": true, "criterion": {"correct": 0.75, "max_repeats": 3},
                "factors": {"edge": [2, 4, 6, 8, 10]}},
               {"name": "main", "factors": {"edge": [1, 2, 3]}}]
  })");
  const auto trials = BuildTrials(p, "P1", 5);
  ASSERT_EQ(trials.size(), 18u);
  std::vector<std::vector<int>> runs(3);
  for (size_t i = 0; i < 15; ++i) {
    EXPECT_EQ(trials[i].block, "warmup");
    EXPECT_TRUE(trials[i].practice);
    EXPECT_EQ(trials[i].round, int(i / 5));
    runs[size_t(trials[i].round)].push_back(ToJson(trials[i].levels)["edge"].get<int>());
  }
  for (auto& run : runs) {
    std::vector<int> sorted = run;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<int>{2, 4, 6, 8, 10}));  // every run is the whole design
  }
  EXPECT_TRUE(runs[0] != runs[1] || runs[1] != runs[2]);  // each run shuffled on its own
  EXPECT_EQ(trials[15].round, -1);
  EXPECT_EQ(ToJson(trials[3])["round"], 0);
}

// Block order: a Williams balanced Latin square over participant numbers - each block once in each place, each
// block right after each other equally often - and a seeded random order.
TEST(TrialBuilder, BlockOrderIsABalancedLatinSquareOrSeeded) {
  for (int n : {2, 3, 4, 5}) {
    Json j = Json::parse(R"({"name": "order", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
                             "content": {"type": "grid"}, "task": "forced_choice", "factors": {"edge": [1]},
                             "sides": {"left": "measured", "right": "estimated"}, "block_order": "latin_square",
                             "blocks": []})");
    for (int b = 0; b < n; ++b) j["blocks"].push_back({{"name", "b" + std::to_string(b)}});
    const Protocol p = ParseProtocol(j, "inline.json", {false});
    const int rows = n % 2 == 0 ? n : 2 * n;
    std::map<std::pair<int, int>, int> place, follows;
    std::mt19937_64 rng(1);
    for (int participant = 0; participant < rows; ++participant) {
      const auto order = BlockOrder(p, "P" + std::to_string(participant), rng);
      ASSERT_EQ(order.size(), size_t(n));
      for (int k = 0; k < n; ++k) {
        ++place[{int(order[size_t(k)]), k}];
        if (k > 0) ++follows[{int(order[size_t(k) - 1]), int(order[size_t(k)])}];
      }
      // The trial list runs the blocks in that order.
      const auto trials = BuildTrials(p, "P" + std::to_string(participant), 7);
      for (int k = 0; k < n; ++k) EXPECT_EQ(trials[size_t(k)].block, "b" + std::to_string(order[size_t(k)]));
    }
    for (int b = 0; b < n; ++b)
      for (int k = 0; k < n; ++k) EXPECT_EQ((place[{b, k}]), rows / n) << "n " << n << " block " << b << " place " << k;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        if (a != b) {
          EXPECT_EQ((follows[{a, b}]), rows / n) << "n " << n << ": " << a << " then " << b;
        }
    EXPECT_THROW(BuildTrials(p, "anonymous", 7), Error);
    j["block_order"] = "random";
    const Protocol r = ParseProtocol(j, "inline.json", {false});
    std::set<std::vector<std::string>> seen;
    for (uint64_t seed = 0; seed < 40; ++seed) {
      std::vector<std::string> names;
      for (const auto& t : BuildTrials(r, "P1", seed)) names.push_back(t.block);
      seen.insert(names);
      std::vector<std::string> again;
      for (const auto& t : BuildTrials(r, "P1", seed)) again.push_back(t.block);
      EXPECT_EQ(names, again);
    }
    EXPECT_GT(seen.size(), size_t(n == 2 ? 1 : 3));
  }
}

// Practice blocks run first, in the order the file gives them, under every block order; random and latin_square
// order only the scored blocks. The random order's draws are those of a shuffle of every block, so the scored blocks
// keep the order the same seed gave them before, and a Latin square balances the scored blocks among themselves.
TEST(TrialBuilder, PracticeBlocksComeFirstUnderEveryBlockOrder) {
  Json j = Json::parse(R"({"name": "order", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
    "content": {"type": "grid"}, "task": "forced_choice", "factors": {"edge": [1]},
    "sides": {"left": "measured", "right": "estimated"},
    "blocks": [{"name": "a"}, {"name": "warm", "practice": true}, {"name": "b"}, {"name": "c"},
               {"name": "warm2", "practice": true}]})");
  auto blocks_of = [](const std::vector<Trial>& trials) {
    std::vector<std::string> names;
    for (const auto& t : trials) names.push_back(t.block);
    return names;
  };
  auto scored_of = [](std::vector<std::string> names) {
    names.erase(std::remove_if(names.begin(), names.end(), [](const std::string& n) { return n.rfind("warm", 0) == 0; }),
                names.end());
    return names;
  };
  for (const char* order : {"fixed", "random", "latin_square"}) {
    j["block_order"] = order;
    const Protocol p = ParseProtocol(j, "inline.json", {false});
    std::map<std::pair<std::string, int>, int> place;
    for (int participant = 1; participant <= 12; ++participant) {
      const std::string id = "P" + std::to_string(participant);
      const auto names = blocks_of(BuildTrials(p, id, uint64_t(participant)));
      ASSERT_EQ(names.size(), 5u) << order;
      EXPECT_EQ(names[0], "warm") << order << " " << id;
      EXPECT_EQ(names[1], "warm2") << order << " " << id;
      for (int k = 2; k < 5; ++k) ++place[{names[size_t(k)], k}];
      if (std::string(order) == "fixed") {
        EXPECT_EQ(scored_of(names), (std::vector<std::string>{"a", "b", "c"}));
      }
      if (std::string(order) == "random") {
        // The same seed orders the scored blocks as it does with no practice blocks among them.
        Json plain = j;
        for (auto& b : plain["blocks"]) b.erase("practice");
        const Protocol q = ParseProtocol(plain, "inline.json", {false});
        EXPECT_EQ(scored_of(names), scored_of(blocks_of(BuildTrials(q, id, uint64_t(participant))))) << id;
      }
    }
    // Three scored blocks: a Williams square of 6 rows, each block twice in each place over 12 participants.
    if (std::string(order) == "latin_square") {
      for (const char* b : {"a", "b", "c"})
        for (int k = 2; k < 5; ++k) EXPECT_EQ((place[{b, k}]), 4) << b << " place " << k;
    }
  }
}

// Groups: by participant number in turn, or the group with the fewest sessions so far; a session's trials are
// its group's blocks (and the blocks of every group).
TEST(TrialBuilder, GroupsAreAssignedAndSelectTheirBlocks) {
  const Protocol p = FromJson(R"({
    "name": "groups", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
    "content": {"type": "grid"}, "task": "forced_choice", "factors": {"edge": [1, 2]},
    "sides": {"left": "measured", "right": "none"},
    "groups": {"names": ["a", "b", "c"]},
    "blocks": [{"name": "all"}, {"name": "for-a", "groups": ["a"]}, {"name": "for-bc", "groups": ["b", "c"]}]
  })");
  EXPECT_EQ(AssignGroup(p, "P1", {}), "a");
  EXPECT_EQ(AssignGroup(p, "P2", {}), "b");
  EXPECT_EQ(AssignGroup(p, "P3", {}), "c");
  EXPECT_EQ(AssignGroup(p, "P4", {}), "a");
  EXPECT_EQ(AssignGroup(p, "P0", {}), "c");
  EXPECT_THROW(AssignGroup(p, "anonymous", {}), Error);
  Protocol balanced = p;
  balanced.groups->assign = GroupAssign::kBalanced;
  EXPECT_EQ(AssignGroup(balanced, "anonymous", {}), "a");
  EXPECT_EQ(AssignGroup(balanced, "x", {{"a", 3}, {"b", 2}, {"c", 2}}), "b");
  EXPECT_EQ(AssignGroup(balanced, "x", {{"a", 1}, {"b", 2}, {"c", 2}}), "a");
  std::set<std::string> blocks_a, blocks_b;
  for (const auto& t : BuildTrials(p, "P1", 5, "a")) blocks_a.insert(t.block);
  for (const auto& t : BuildTrials(p, "P1", 5, "b")) blocks_b.insert(t.block);
  EXPECT_EQ(blocks_a, (std::set<std::string>{"all", "for-a"}));
  EXPECT_EQ(blocks_b, (std::set<std::string>{"all", "for-bc"}));
}

// A practice block: its own design, its trials recorded as practice; a protocol of practice blocks alone is refused.
TEST(TrialBuilder, PracticeBlocksAreRecordedAsPractice) {
  const char* text = R"({"name": "practice", "version": 1, "scene": {"background": "s.png", "calib": "c.json"},
    "content": {"type": "grid"}, "task": "forced_choice", "sides": {"left": "measured", "right": "none"},
    "blocks": [{"name": "warm-up", "practice": true, "factors": {"edge": [11]}},
               {"name": "main", "factors": {"edge": [2, 5, 8]}}]})";
  const auto trials = BuildTrials(FromJson(text), "P1", 3);
  ASSERT_EQ(trials.size(), 4u);
  EXPECT_TRUE(trials[0].practice);
  EXPECT_EQ(trials[0].block, "warm-up");
  for (size_t i = 1; i < trials.size(); ++i) EXPECT_FALSE(trials[i].practice);
  Json only = Json::parse(text);
  only["blocks"].erase(1);
  EXPECT_THROW(ParseProtocol(only, "inline.json", {false}), Error);
}

TEST(TrialBuilder, GeneratorIsTheStandardMt19937_64) {
  // The C++ standard fixes the 10000th output of a default-constructed mt19937_64.
  std::mt19937_64 rng;
  rng.discard(9999);
  EXPECT_EQ(rng(), 9981545732273789042ull);
}

TEST(TrialBuilder, FisherYatesMatchesHandComputedPermutation) {
  // Expected order from raw generator outputs: for i = 3, 2, 1 swap position i with x % (i + 1).
  // (Rejection only skips outputs below 2^64 mod (i + 1), at most 3 of 2^64; checked, not assumed.)
  std::mt19937_64 raw(42);
  std::vector<int> expected = {1, 2, 3, 4};
  for (int i = 3; i >= 1; --i) {
    const uint64_t x = raw();
    ASSERT_GE(x, 4u);
    std::swap(expected[i], expected[x % (i + 1)]);
  }
  EXPECT_EQ(Edges(BuildTrials(FromJson(kFour), "P1", 42)), expected);
}

TEST(TrialBuilder, SameSeedSameOrder) {
  const Protocol p = Shipped("test2-moving-balls.json");
  const auto a = BuildTrials(p, "P3", 2024);
  const auto b = BuildTrials(p, "P3", 2024);
  EXPECT_EQ(ToJson(a), ToJson(b));
  EXPECT_EQ(TrialsHash(a), TrialsHash(b));
}

TEST(TrialBuilder, RecordedHashIsStable) {
  // Recorded from a first run; any change to the generator, the shuffle, the crossing order or the trial JSON
  // changes it (and must be a deliberate, documented change: stored sessions name their hash).
  EXPECT_EQ(HashHex(TrialsHash(BuildTrials(FromJson(kFour), "P1", 7))), "7ee6a5a1e18a2389");
}

TEST(TrialBuilder, DifferentSeedsDiffer) {
  const Protocol p = Shipped("test2-moving-balls.json");
  EXPECT_NE(TrialsHash(BuildTrials(p, "P1", 1)), TrialsHash(BuildTrials(p, "P1", 2)));
  EXPECT_NE(ToJson(BuildTrials(p, "P1", 1)), ToJson(BuildTrials(p, "P1", 2)));
}

TEST(TrialBuilder, EveryLevelAppearsAsDesigned) {
  // Test 2's task 2: patterns 2, 4, 6 x sections 1..10 x 2 sides: each (pattern, section) twice, once swapped.
  const auto trials = BuildTrials(Shipped("test2-moving-balls.json"), "P1", 5);
  std::map<std::pair<int, int>, int> plain, swapped;
  for (const auto& t : trials) {
    if (t.practice || t.block != "task2") continue;
    auto& counts = t.swapped ? swapped : plain;
    ++counts[{ToJson(t.levels)["pattern"]["id"].get<int>(), ToJson(t.levels)["section"].get<int>()}];
  }
  ASSERT_EQ(plain.size(), 30u);
  ASSERT_EQ(swapped.size(), 30u);
  for (int id : {2, 4, 6})
    for (int s = 1; s <= 10; ++s) {
      EXPECT_EQ((plain[{id, s}]), 1) << id << " " << s;
      EXPECT_EQ((swapped[{id, s}]), 1) << id << " " << s;
    }
}

TEST(TrialBuilder, SwapCopiesPutEachSourceOnEachSideEquallyOften) {
  const auto trials = BuildTrials(Shipped("test2-moving-balls.json"), "P1", 9);
  std::map<std::pair<int, std::string>, int> on_left;  // (pattern, source) -> times shown left
  for (const auto& t : trials) {
    if (t.practice || t.block != "task1") continue;
    const Json design = ToJson(t.levels)["pattern"];
    EXPECT_EQ(ToJson(t.left), t.swapped ? design["right"] : design["left"]);
    EXPECT_EQ(ToJson(t.right), t.swapped ? design["left"] : design["right"]);
    ++on_left[{design["id"].get<int>(), ToJson(t.left).get<std::string>()}];
  }
  const Protocol p = Shipped("test2-moving-balls.json");
  ASSERT_EQ(p.blocks[0].factors[0].levels.size(), 6u);
  for (const Level& typed : p.blocks[0].factors[0].levels) {
    const Json level = ToJson(typed);
    const int id = level["id"].get<int>();
    EXPECT_EQ((on_left[{id, level["left"].get<std::string>()}]), 1) << id;
    EXPECT_EQ((on_left[{id, level["right"].get<std::string>()}]), 1) << id;
  }
}

TEST(TrialBuilder, ByParticipantSwapsForEvenNumbers) {
  const Protocol p = Shipped("test1-static-grids.json");
  for (const auto& t : BuildTrials(p, "P7", 1)) {
    EXPECT_FALSE(t.swapped);
    EXPECT_EQ(ToJson(t.left), "measured");
  }
  for (const auto& t : BuildTrials(p, "P8", 1)) {
    EXPECT_TRUE(t.swapped);
    EXPECT_EQ(ToJson(t.left), "estimated");
    EXPECT_EQ(ToJson(t.right), "measured");
  }
}

TEST(TrialBuilder, ByParticipantNeedsANumberedParticipant) {
  try {
    BuildTrials(Shipped("test1-static-grids.json"), "anna", 1);
    FAIL() << "built";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    // Names the field that asked for it.
    EXPECT_NE(std::string(e.what()).find("test1-static-grids.json: /counterbalance: by_participant"),
              std::string::npos) << e.what();
  }
}

TEST(TrialBuilder, ParticipantNumberIsTheTrailingDigits) {
  EXPECT_EQ(ParticipantNumber("P12"), 12);
  EXPECT_EQ(ParticipantNumber("7"), 7);
  EXPECT_EQ(ParticipantNumber("P"), -1);
}

TEST(TrialBuilder, PracticeFirstThenBlocksInOrder) {
  const auto trials = BuildTrials(Shipped("test2-moving-balls.json"), "P1", 3);
  ASSERT_EQ(trials.size(), 74u);
  for (size_t i = 0; i < trials.size(); ++i) {
    EXPECT_EQ(trials[i].index, static_cast<int>(i));
    EXPECT_EQ(trials[i].practice, i < 2);
    EXPECT_EQ(trials[i].block, i < 14 ? "task1" : "task2") << i;
  }
}

TEST(TrialBuilder, RepetitionsMultiplyTheDesign) {
  Json j = Json::parse(kFour);
  j["repetitions"] = 3;
  const auto trials = BuildTrials(ParseProtocol(j, "inline.json", {false}), "P1", 1);
  ASSERT_EQ(trials.size(), 12u);
  std::map<int, int> counts;
  for (const auto& t : trials) ++counts[ToJson(t.levels)["edge"].get<int>()];
  for (int e = 1; e <= 4; ++e) EXPECT_EQ(counts[e], 3);
}

TEST(TrialBuilder, AdjustmentLevelsAndStartAreDrawnPerTrial) {
  const Protocol p = Shipped("pre-research-depth-matching.json");
  const auto trials = BuildTrials(p, "P1", 11);
  std::vector<double> sorted_levels = p.blocks[0].adjust->levels;
  std::sort(sorted_levels.begin(), sorted_levels.end());
  std::set<std::vector<double>> orders;
  std::set<int> starts;
  std::set<double> distances;
  for (const auto& t : trials) {
    std::vector<double> levels = t.adjust_levels;
    std::sort(levels.begin(), levels.end());
    EXPECT_EQ(levels, sorted_levels);  // a permutation of the 22 cut-offs
    ASSERT_GE(t.start_index, 0);
    ASSERT_LT(t.start_index, 22);
    orders.insert(t.adjust_levels);
    starts.insert(t.start_index);
    if (!t.practice) distances.insert(ToJson(t.levels)["distance_m"].get<double>());
    EXPECT_EQ(ToJson(t)["start_index"], t.start_index);
  }
  EXPECT_EQ(distances.size(), 27u);
  EXPECT_EQ(orders.size(), trials.size());  // 28 orders of 22 levels: a repeat would mean no fresh draw
  EXPECT_GT(starts.size(), 5u);
}

TEST(TrialBuilder, UnshuffledBlockKeepsTheCrossingOrder) {
  Json j = Json::parse(kFour);
  j["blocks"] = {{{"name", "fixed"}, {"shuffle", false}}};
  EXPECT_EQ(Edges(BuildTrials(ParseProtocol(j, "inline.json", {false}), "P1", 1)), (std::vector<int>{1, 2, 3, 4}));
}

TEST(TrialBuilder, UniformBelowStaysInRange) {
  std::mt19937_64 rng(1);
  std::vector<int> counts(3);
  for (int i = 0; i < 3000; ++i) ++counts[UniformBelow(rng, 3)];
  for (int c : counts) EXPECT_GT(c, 850);
}

}  // namespace
}  // namespace blurcue::protocol

namespace blurcue::protocol {
namespace {

TEST(TrialPointers, SideNamesTheLevelThatChoseIt) {
  const Protocol p = Shipped("test2-moving-balls.json");
  bool saw_swapped = false, saw_plain = false;
  for (const auto& t : BuildTrials(p, "P1", 3)) {
    if (t.practice || t.block != "task2") continue;
    const int at = ToJson(t.levels)["pattern"]["id"].get<int>() / 2 - 1;  // task 2 lists patterns 2, 4, 6
    const std::string level = "/blocks/1/factors/pattern/" + std::to_string(at);
    // A swapped copy shows the design's right source on the left.
    EXPECT_EQ(SidePointer(p, t, Side::kLeft), level + (t.swapped ? "/right" : "/left"));
    EXPECT_EQ(SidePointer(p, t, Side::kRight), level + (t.swapped ? "/left" : "/right"));
    EXPECT_EQ(LevelPointer(p, t, "section"),
              "/blocks/1/factors/section/" + std::to_string(ToJson(t.levels)["section"].get<int>() - 1));
    EXPECT_EQ(LevelPointer(p, t, "speed_cm_s"), level + "/speed_cm_s");
    (t.swapped ? saw_swapped : saw_plain) = true;
  }
  EXPECT_TRUE(saw_swapped && saw_plain);
}

TEST(TrialPointers, SidesObjectOfTheProtocolWhenNoLevelCarriesThem) {
  const Protocol p = Shipped("test1-static-grids.json");
  const auto trials = BuildTrials(p, "P2", 1);  // even: every trial swapped
  EXPECT_EQ(SidePointer(p, trials.back(), Side::kLeft), "/sides/right");
  EXPECT_EQ(LevelPointer(p, trials.back(), "edge"),
            "/factors/edge/" + std::to_string(ToJson(trials.back().levels)["edge"].get<int>() - 1));
}

TEST(TrialBuilder, ProtocolOverTheTrialCapIsRefusedBeforeBuilding) {
  Protocol p = FromJson(kFour);
  Factor big{"big", {}};
  for (int i = 0; i < 1000; ++i) big.levels.push_back(LevelOf("big", i));
  for (int k = 0; k < 8; ++k) p.blocks[0].factors.push_back(big);  // 4 x 1000^8: would never fit in memory
  try {
    BuildTrials(p, "P1", 1);
    FAIL() << "built";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("more than 10000 trials"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace blurcue::protocol
