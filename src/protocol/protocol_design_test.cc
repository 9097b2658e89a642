#include "protocol/protocol.h"
#include "blurcue/source_dir.h"

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "protocol/protocol_test_util.h"
#include "protocol/trials.h"

namespace blurcue::protocol {
namespace {

using namespace test;  // NOLINT: the helpers every test here uses

TEST(ProtocolValidate, ValidProtocolHasNoProblems) {
  const auto problems = Problems(Valid());
  EXPECT_TRUE(problems.empty()) << problems.front();
}

// The kernel and the brightness/contrast matching are protocol fields with ranges; a grid count other than the
// shipped card's would be recorded but not drawn, so it is refused.
TEST(ProtocolValidate, KernelBrightnessContrastWhiteBalanceScaleAndCellsAreCheckedNotIgnored) {
  Json j = Valid();
  j["content"]["kernel"] = "disc";
  j["content"]["brightness"] = 1.2;
  j["content"]["contrast"] = 0.9;
  EXPECT_TRUE(Problems(j).empty());
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  EXPECT_EQ(p.content.kernel, Kernel::kDisc);
  EXPECT_DOUBLE_EQ(p.content.brightness, 1.2);
  j["content"]["kernel"] = "box";
  EXPECT_TRUE(Contains(OnlyProblem(j), "/content/kernel")) << OnlyProblem(j);
  j["content"]["kernel"] = "gaussian";
  j["content"]["contrast"] = 10;
  EXPECT_TRUE(Contains(OnlyProblem(j), "/content/contrast")) << OnlyProblem(j);
  j["content"]["contrast"] = 1;
  j["content"]["white_balance"] = {1.0, 0.9, 1.1};
  EXPECT_TRUE(Problems(j).empty());
  EXPECT_DOUBLE_EQ(ParseProtocol(j, SceneFolder() / "p.json").content.white_balance[2], 1.1);
  for (const Json& bad : {Json::array({1, 1}), Json::array({1, 1, 9}), Json(1.0), Json::array({1, "1", 1})}) {
    j["content"]["white_balance"] = bad;
    EXPECT_TRUE(Contains(OnlyProblem(j), "/content/white_balance: must be [red, green, blue] gains")) << OnlyProblem(j);
  }
  j["content"].erase("white_balance");
  // A fixed radius on the screen, in screen px or arcmin, is a blur source; other units are not.
  Json sized = Valid();
  sized["sides"] = {{"left", {{"arcmin", 2}}}, {"right", {{"screen_px", 1.5}}}};
  sized["blocks"][0]["factors"]["pattern"] = {{{"id", 1}, {"speed_cm_s", 3}}};
  sized["blocks"][1]["factors"]["pattern"] = {{{"id", 2}, {"speed_cm_s", 3}}};
  EXPECT_TRUE(Problems(sized).empty()) << Problems(sized).front();
  for (const Json& bad : {Json{{"arcmin", -1}}, Json{{"deg", 1}}, Json{{"arcmin", 1}, {"screen_px", 1}}}) {
    sized["sides"]["left"] = bad;
    bool named = false;
    for (const auto& problem : Problems(sized)) named = named || Contains(problem, "/sides/left: a blur source must be");
    EXPECT_TRUE(named) << bad.dump() << ": " << Problems(sized).front();
  }
  // A display scale or width in degrees is for a photo's grid or ball; each is checked, and not both at once.
  Json shown = Valid();
  shown["display"] = {{"scale", "native"}};
  EXPECT_TRUE(Problems(shown).empty());
  EXPECT_EQ(ParseProtocol(shown, SceneFolder() / "p.json").display.scaling, Scaling::kNative);
  shown["display"] = {{"scale", 0.01}};
  EXPECT_TRUE(Contains(OnlyProblem(shown), "/display/scale: must be \"fit\", \"native\"")) << OnlyProblem(shown);
  shown["display"] = {{"scale", 0.5}, {"width_deg", 20}};
  EXPECT_TRUE(Contains(OnlyProblem(shown), "/display/width_deg: give either")) << OnlyProblem(shown);
  // A level that places or moves a stimulus is refused where the content does not read it.
  Json still = Valid();
  still["content"] = {{"type", "grid"}};
  still["factors"] = {{"edge", {1, 2}}, {"speed_cm_s", {3}}};
  still["sides"] = {{"left", "measured"}, {"right", "estimated"}};
  still.erase("blocks");
  bool unused = false;
  for (const auto& problem : Problems(still))
    unused = unused || Contains(problem, "/factors/speed_cm_s: a grid does not use speed_cm_s");
  EXPECT_TRUE(unused) << Problems(still).front();
  Json grid = Valid();
  grid["content"] = {{"type", "grid"}, {"cells", 25}};  // 1-20 cells are drawn; 25 would be recorded but not shown
  bool named = false;
  for (const auto& problem : Problems(grid)) named = named || Contains(problem, "/content/cells");
  EXPECT_TRUE(named);
}

// An adaptive block: each field of its procedure checked with its pointer, and the design fields the procedure
// decides refused there.
TEST(ProtocolValidate, ProceduresAreCheckedAndOwnTheirSidesAndCounts) {
  Json j = Json::parse(R"({
    "name": "adaptive", "version": 1,
    "scene": {"background": "scene/scene.png", "calib": "calib.json"},
    "content": {"type": "grid"}, "task": "forced_choice",
    "blocks": [
      {"name": "quest", "factors": {"edge": [5, 9]},
       "procedure": {"type": "quest_plus", "variable": "difference_arcmin", "reference": "measured", "trials": 20,
                     "stimuli": [0.5, 1, 2, 4], "threshold": [0.5, 1, 2], "slope": [2, 3.5], "lapse": [0, 0.02]}},
      {"name": "stairs", "factors": {"edge": [3]},
       "procedure": {"type": "staircase", "variable": "relative_difference", "reference": "fitted", "trials": 10,
                     "start": 1, "min": 0.05, "max": 2, "steps": [0.4, 0.2]}}
    ],
    "responses": {"left": "Left", "right": "Right", "cant_tell": null}
  })");
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  ASSERT_TRUE(p.blocks[0].procedure && p.blocks[1].procedure);
  EXPECT_EQ(p.blocks[0].procedure->kind, Procedure::Kind::kQuestPlus);
  EXPECT_EQ(p.blocks[1].procedure->steps, (std::vector<double>{0.4, 0.2}));
  EXPECT_EQ(SessionTrials(p), 2 * 20 + 10);  // each crossing runs its own procedure
  EXPECT_TRUE(p.responses.cant_tell.empty());  // a strict 2AFC
  Json bad = j;
  bad["blocks"][0]["procedure"]["variable"] = "gain";
  ExpectProblem(bad, "/blocks/0/procedure/variable: must be one of");
  bad = j;
  bad["blocks"][0]["procedure"]["stimuli"] = {1, 0.5};
  ExpectProblem(bad, "/blocks/0/procedure/stimuli/1: must be larger than the one before");
  bad = j;
  bad["blocks"][0]["procedure"]["lapse"] = {0.6};
  ExpectProblem(bad, "/blocks/0/procedure/lapse/0: must be a number in [0, 0.5]");
  bad = j;
  bad["blocks"][1]["procedure"]["start"] = 3;
  ExpectProblem(bad, "/blocks/1/procedure/start: must lie in [min, max]");
  bad = j;
  bad["blocks"][1]["procedure"].erase("steps");
  ExpectProblem(bad, "/blocks/1/procedure/steps: is required");
  bad = j;
  bad["blocks"][1]["procedure"]["tries"] = 3;
  ExpectProblem(bad, "/blocks/1/procedure/tries: unknown key");
  bad = j;
  bad["blocks"][1]["sides"] = {{"left", "measured"}, {"right", "none"}};
  ExpectProblem(bad, "/blocks/1/sides: is given but the procedure shows its reference on both sides");
  bad = j;
  bad["blocks"][1]["repetitions"] = 2;
  ExpectProblem(bad, "/blocks/1/procedure/trials: sets how often each crossing runs");
  bad = j;
  bad["practice"] = {{"count", 2}, {"block", "stairs"}};
  ExpectProblem(bad, "/practice/block: names block stairs, whose trials its procedure decides");
}

// A conditions table instead of factors: each CSV row one design row (not a full crossing), numbers read as
// numbers, sides from its left/right columns, every cell checked with a pointer to its row and column.
TEST(ProtocolValidate, ConditionsTableGivesTheDesignRowByRow) {
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "rows.csv") << "edge,speed_cm_s,left,right,label\r\n1,3,measured,none,\"near, fast\"\r\n"
                                     "9,1.8,estimated,none,far\r\n";
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "rows.csv"}}};
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
  const Protocol p = ParseProtocol(j, dir / "p.json");
  ASSERT_EQ(p.blocks[0].factors.size(), 1u);
  EXPECT_EQ(p.blocks[0].factors[0].levels.size(), 2u);
  EXPECT_EQ(ToJson(p.blocks[0].factors[0].levels[0])["label"], "near, fast");
  EXPECT_EQ(ToJson(p.blocks[0].factors[0].levels[1])["speed_cm_s"], 1.8);
  EXPECT_EQ(DesignTrials(p.blocks[0]), 2 * 2);  // two rows x the protocol's swap_copies
  std::ofstream(dir / "bad.csv") << "edge,left,right\n102,measured,none\n3,measured\n";
  j["blocks"][0]["conditions"] = "bad.csv";
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(Contains(problems[0], "bad.csv line 2, column 1 (edge): an edge must be an integer in [1, 101], got 102"))
      << problems[0];
  EXPECT_TRUE(Contains(problems[1], "bad.csv line 3: has 2 fields, the header 3")) << problems[1];
  // A cell is a number only as a decimal: "0x9" (which strtod reads as edge 9) and " 9" are text, refused as edges.
  for (const char* edge : {"0x9", " 9", "9 ", "nan"}) {
    std::ofstream(dir / "odd.csv") << "edge,left,right\n" << edge << ",measured,none\n";
    j["blocks"][0]["conditions"] = "odd.csv";
    EXPECT_TRUE(Contains(OnlyProblem(j), "odd.csv line 2, column 1 (edge): an edge must be an integer")) << edge;
  }
  j["blocks"][0]["conditions"] = "bad.csv";
  j["blocks"][0]["factors"] = {{"edge", {1}}};
  EXPECT_TRUE(Contains(Problems(j).front(), "give either factors or a conditions table")) << Problems(j).front();
  j["blocks"][0].erase("factors");
  j["blocks"][0]["conditions"] = "missing.csv";
  EXPECT_TRUE(Contains(OnlyProblem(j), "/blocks/0/conditions: no such file")) << OnlyProblem(j);
}

// A table saved by Excel ("CSV UTF-8") or Notepad begins with a byte order mark: it used to become part of the
// first column's name, so "edge" was refused as an unknown column that looked like edge. A header name with a space
// at its end ("edge ") is refused with the name quoted, the space said; it used to read "a column edge  (did you
// mean edge?)".
TEST(ProtocolValidate, ConditionsTableWithAByteOrderMarkReadsItsFirstColumn) {
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "bom.csv") << "\xEF\xBB\xBF" "edge,left,right\r\n1,measured,none\r\n";
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "bom.csv"}}};
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
  const Protocol p = ParseProtocol(j, dir / "p.json");
  EXPECT_EQ(ToJson(p.blocks[0].factors[0].levels[0])["edge"], 1);
  std::ofstream(dir / "padded.csv") << "edge ,left,right\n1,measured,none\n";
  j["blocks"][0]["conditions"] = "padded.csv";
  const std::string problem = OnlyProblem(j);
  EXPECT_TRUE(Contains(problem, "column \"edge \" (a space at its start or end) (did you mean edge?)")) << problem;
}

// A conditions table's cell that is not UTF-8 (a Latin-1 file's "é" or stray bytes) is a problem naming the CSV
// file, its line and column, and the cell's pointer; it used to pass and stop validate, run, preview and plan with
// the JSON library's "invalid UTF-8 byte" (exit 10) when the trial list was hashed.
TEST(ProtocolValidate, ConditionsTableCellThatIsNotUtf8IsRefusedNamingFileLineAndColumn) {
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "latin1.csv") << "edge,left,right,label\n1,measured,none,ok\n2,measured,none,caf\xe9\xff\xfe\n";
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "latin1.csv"}}};
  const std::string problem = OnlyProblem(j);
  EXPECT_TRUE(Contains(problem, "p.json: " + (dir / "latin1.csv").string() + " line 3, column 4 (label): must be "
                                "printable UTF-8 text")) << problem;
  EXPECT_TRUE(Contains(problem, "got 'caf\\xe9\\xff\\xfe'")) << problem;
  try {
    ParseProtocol(j, dir / "p.json");
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
  }
}

// A NUL, escape or other control byte in a cell is refused as in a protocol's own names: it used to be written raw
// into the record's trials.
TEST(ProtocolValidate, ConditionsTableCellWithAControlByteIsRefused) {
  const fs::path dir = SceneFolder();
  const char text[] = "edge,left,right,label\n1,measured,none,o\0k\n2,measured,none,a\x1b[2Jb\n3,measured,none,\"tab\there\"\n";
  std::ofstream(dir / "controls.csv") << std::string(text, sizeof text - 1);
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "controls.csv"}}};
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_TRUE(Contains(problems[0], (dir / "controls.csv").string() + " line 2, column 4 (label): "
                                    "must be printable UTF-8 text")) << problems[0];
  EXPECT_TRUE(Contains(problems[0], "got 'o\\x00k'")) << problems[0];
  EXPECT_TRUE(Contains(problems[1], "controls.csv line 3, column 4 (label): ")) << problems[1];
  EXPECT_TRUE(Contains(problems[1], "got 'a\\x1b[2Jb'")) << problems[1];
  EXPECT_TRUE(Contains(problems[2], "controls.csv line 4, column 4 (label): ")) << problems[2];
}

// A quote left open to the end of the file is a problem naming the file, the line and the column where it opened:
// the table `2,measured,none,"ab` used to validate and record the label `ab`. The line counts the file's lines,
// blank ones included.
TEST(ProtocolValidate, ConditionsTableUnclosedQuoteIsRefusedNamingTheLine) {
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "open.csv") << "edge,left,right,label\n1,measured,none,\"a \"\"b\"\"\"\n\n2,measured,none,\"ab\n";
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "open.csv"}}};
  const std::string problem = OnlyProblem(j);
  EXPECT_TRUE(Contains(problem, "/blocks/0/conditions: " + (dir / "open.csv").string() +
                                    " line 4, column 17: a quoted field is not closed")) << problem;
  std::ofstream(dir / "open-header.csv") << "edge,left,right,\"label\n1,measured,none,x\n";
  j["blocks"][0]["conditions"] = "open-header.csv";
  EXPECT_TRUE(Contains(OnlyProblem(j), "open-header.csv line 1, column 17: a quoted field is not closed"))
      << OnlyProblem(j);
  // Closed quotes still read as before: "" is one quote.
  std::ofstream(dir / "open.csv") << "edge,left,right,label\n1,measured,none,\"a \"\"b\"\"\"\n";
  j["blocks"][0]["conditions"] = "open.csv";
  EXPECT_EQ(ToJson(ParseProtocol(j, dir / "p.json").blocks[0].factors[0].levels[0])["label"], "a \"b\"");
}

// The real photos of a depth matching are chosen by distance_m wherever a trial finds it: its own factor, a key of
// an object level, or a conditions table's column (the table was refused: "needs a factor distance_m").
TEST(ProtocolValidate, RealPhotoDistancesComeFromFactorsObjectLevelsAndConditionsTables) {
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "dm.csv") << "distance_m\n0.4\n1.092\n";
  auto distances = [&](const Json& design) {
    Json j = Json::parse(R"({"name": "dm", "version": 1, "scene": {"background": "s.png"},
                             "content": {"type": "picture", "image": "face.png"},
                             "task": "adjustment", "adjust": {"parameter": "cutoff", "levels": [2, 4, 8]}})");
    for (const auto& [k, v] : design.items()) j[k] = v;
    return NumericLevels(ParseProtocol(j, dir / "p.json", ValidateOptions{false}), "distance_m");
  };
  const std::set<double> want = {0.4, 1.092};
  EXPECT_EQ(distances(Json::parse(R"({"factors": {"distance_m": [0.4, 1.092]}})")), want);
  EXPECT_EQ(distances(Json::parse(R"({"factors": {"place": [{"distance_m": 0.4}, {"distance_m": 1.092}]}})")), want);
  EXPECT_EQ(distances(Json::parse(R"({"blocks": [{"name": "b", "conditions": "dm.csv"}]})")), want);
  EXPECT_TRUE(distances(Json::parse(R"({"factors": {"label_other": [1, 2]}})")).empty());
}

// Participant information and between-subject groups: every field checked with its pointer; a block names only
// declared groups; every group runs a block.
TEST(ProtocolValidate, ParticipantInfoAndGroupsAreChecked) {
  Json j = Valid();
  j["participant_info"] = Json::parse(R"([{"key": "age", "type": "integer", "min": 16, "max": 99},
                                          {"key": "hand", "type": "choice", "choices": ["left", "right"]},
                                          {"key": "notes", "required": false}])");
  j["groups"] = {{"names", {"a", "b"}}, {"assign", "balanced"}};
  j["blocks"][0]["groups"] = {"a"};
  j["blocks"][1]["groups"] = {"b"};
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  ASSERT_EQ(p.participant_info.size(), 3u);
  EXPECT_EQ(CheckInfoValue(p.participant_info[0], "34"), "");
  EXPECT_EQ(CheckInfoValue(p.participant_info[0], "34.5"), "must be a whole number in [16, 99]");
  EXPECT_EQ(CheckInfoValue(p.participant_info[0], "nan"), "must be a whole number in [16, 99]");
  EXPECT_EQ(CheckInfoValue(p.participant_info[1], "up"), "must be one of left, right");
  EXPECT_EQ(CheckInfoValue(p.participant_info[2], "bad\nline"), "must be one line of printable text, at most 200 bytes");
  // One reading of a typed number everywhere: hex, a space and "inf" are not an age; broken bytes are not notes.
  for (const char* age : {"0x20", " 34", "34 ", "1e1x", "inf", "3.4e1", "34.", "34.0", "034.0e0"})
    EXPECT_EQ(CheckInfoValue(p.participant_info[0], age), "must be a whole number in [16, 99]") << age;
  EXPECT_EQ(CheckInfoValue(p.participant_info[0], "034"), "");
  EXPECT_NE(CheckInfoValue(p.participant_info[2], "caf\xe9"), "");  // Latin-1, not UTF-8
  EXPECT_EQ(CheckInfoValue(p.participant_info[2], "café"), "");
  Json bad = j;
  bad["participant_info"][0]["key"] = "Age!";
  ExpectProblem(bad, "/participant_info/0/key: must be 1-40 characters of a-z, 0-9 and _");
  bad = j;
  bad["participant_info"][1]["min"] = 1;
  ExpectProblem(bad, "/participant_info/1/min: is for an integer or number field, not choice");
  bad = j;
  bad["participant_info"][0]["max"] = 10;
  ExpectProblem(bad, "/participant_info/0/max: must be larger than min");
  bad = j;
  bad["blocks"][1]["groups"] = {"c"};
  ExpectProblem(bad, "/blocks/1/groups/0: names no group of /groups/names");
  bad = j;
  bad["blocks"][1]["groups"] = {"a"};
  ExpectProblem(bad, "/groups/names: group b runs no block");
  bad = j;
  bad["groups"]["names"] = {"a"};
  ExpectProblem(bad, "/groups/names: must be a list of 2 to 20 group names");
}

// Each group practises its own condition (issue 38): the protocol's practice, drawn from one block for every
// participant, may not come from a block that only some groups run; practice blocks of each group's own are valid.
TEST(ProtocolValidate, APracticeFromAnotherGroupsBlockIsRefused) {
  Json j = Valid();
  j["groups"] = {{"names", {"a", "b"}}, {"assign", "by_number"}};
  j["blocks"][0]["groups"] = {"a"};
  j["blocks"][1]["groups"] = {"b"};
  Json bad = j;
  bad["practice"] = {{"count", 2}, {"block", "task1"}};
  EXPECT_EQ(OnlyProblem(bad), (SceneFolder() / "p.json").string() +
                                  ": /practice/block: names block task1, which only group a runs: group b would "
                                  "practise another group's condition; give each group a practice block of its own "
                                  "(\"practice\": true, \"groups\": [...]) or practise on a block every group runs, "
                                  "got \"task1\"");
  bad["practice"] = {{"count", 2}};  // no block named: the first block's, still group a's only
  EXPECT_TRUE(Contains(OnlyProblem(bad), ": /practice: draws from block task1 (the first; /practice/block names "
                                         "none), which only group a runs: group b would practise"));
  // A block every group runs may be practised by all.
  Json shared = j;
  shared["blocks"][1].erase("groups");
  shared["practice"] = {{"count", 2}, {"block", "task2"}};
  EXPECT_TRUE(Problems(shared).empty()) << Problems(shared).front();
  // No practice trials (count 0) draw nothing.
  Json none = j;
  none["practice"] = {{"count", 0}, {"block", "task1"}};
  EXPECT_TRUE(Problems(none).empty()) << Problems(none).front();
  // A practice block per group: each participant runs their own group's (BuildTrials), none of the other group's.
  Json own = j;
  own["blocks"].insert(own["blocks"].begin(), Json::parse(R"({"name": "practice-b", "practice": true, "groups": ["b"],
      "factors": {"pattern": [{"id": 2, "speed_cm_s": 1.8, "left": "measured", "right": "none"}]}})"));
  own["blocks"].insert(own["blocks"].begin(), Json::parse(R"({"name": "practice-a", "practice": true, "groups": ["a"],
      "factors": {"pattern": [{"id": 1, "speed_cm_s": 3, "left": "measured", "right": "none"}]}})"));
  ASSERT_TRUE(Problems(own).empty()) << Problems(own).front();
  const Protocol p = ParseProtocol(own, SceneFolder() / "p.json");
  for (const auto& [participant, group] : {std::pair{"P1", "a"}, std::pair{"P2", "b"}}) {
    ASSERT_EQ(AssignGroup(p, participant, {}), group);
    int practised = 0;
    for (const Trial& t : BuildTrials(p, participant, 7, group))
      if (t.practice) {
        ++practised;
        EXPECT_EQ(t.block, std::string("practice-") + group) << participant;
      }
    EXPECT_EQ(practised, 2) << participant;  // the practice block's design, swapped copies
  }
}

// An up/down rule whose convergence point is at or below the guess rate measures no threshold: refused, naming the
// rule's share (3-up/1-down: 1 - 0.5^(1/3) = 20.6 %; 1-up/1-down: 50 %, a 2AFC's guessing). 1-up/2-down passes.
TEST(ProtocolValidate, AStaircaseConvergingOnGuessingIsRefused) {
  Json j = Valid();
  j["blocks"] = Json::parse(R"([{"name": "s", "factors": {"edge": [3]},
      "procedure": {"type": "staircase", "variable": "relative_difference", "reference": "measured", "trials": 20,
                    "start": 1, "min": 0.05, "max": 2, "up": 3, "down": 1, "steps": [0.2]}}])");
  j["counterbalance"] = "none";
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/0/procedure/down: a 3-up/1-down staircase converges on 20.6 % "
                                       "correct, at or below what guessing gives here (50.0 %)"))
      << OnlyProblem(j);
  j["blocks"][0]["procedure"]["up"] = 1;
  EXPECT_TRUE(Contains(OnlyProblem(j), "a 1-up/1-down staircase converges on 50.0 % correct")) << OnlyProblem(j);
  j["blocks"][0]["procedure"]["down"] = 2;
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
  EXPECT_NEAR(StaircaseTarget(1, 2), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(StaircaseTarget(3, 1), 1 - std::cbrt(0.5), 1e-12);
}

// A practice block of a group's own must show that group's condition: its sides those of a block the group runs,
// not only of another group's (the adversary's practice block for one group showing the other's sides: accepted).
TEST(ProtocolValidate, AGroupsPracticeBlockShowsItsOwnCondition) {
  Json j = Valid();
  j["groups"] = {{"names", {"a", "b"}}, {"assign", "by_number"}};
  j["blocks"] = Json::parse(R"([
      {"name": "main-a", "groups": ["a"], "factors": {"speed_cm_s": [3]}, "sides": {"left": "measured", "right": "estimated"}},
      {"name": "main-b", "groups": ["b"], "factors": {"speed_cm_s": [3]}, "sides": {"left": "measured", "right": "none"}},
      {"name": "practice-b", "practice": true, "groups": ["b"], "factors": {"speed_cm_s": [3]},
       "sides": {"left": "measured", "right": "estimated"}}])");
  EXPECT_TRUE(Contains(OnlyProblem(j), ": /blocks/2/sides: practice block practice-b for group b shows the sides of "
                                       "block main-a, which group b never runs: it would practise another group's "
                                       "condition"))
      << OnlyProblem(j);
  j["blocks"][2]["sides"]["right"] = "none";  // group b's own condition
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
}

// Two intervals: timed by interval_ms and isi_ms (which a side-by-side protocol refuses), still pairs only.
TEST(ProtocolValidate, TwoIntervalsAreTimedAndStill) {
  Json j = Valid();
  j["timing"] = {{"interval_ms", 800}};
  EXPECT_TRUE(Contains(OnlyProblem(j), "/timing/interval_ms: is for the layouts two_intervals and odd_one_out")) << OnlyProblem(j);
  j["layout"] = "two_intervals";
  bool moving = false;  // the valid protocol's balls roll at a speed
  for (const auto& problem : Problems(j)) moving = moving || Contains(problem, "intervals show still objects");
  EXPECT_TRUE(moving);
  j["timing"]["stimulus_ms"] = 500;
  bool timed = false;
  for (const auto& problem : Problems(j)) timed = timed || Contains(problem, "/timing/stimulus_ms: intervals are timed");
  EXPECT_TRUE(timed);
}

// One object (layout single): answered yes/no or rated, its source an "object"; a pair's fields are refused there and
// the single layout's everywhere else.
Json Single() {
  Json j = Valid();
  j["layout"] = "single";
  j.erase("counterbalance");
  j["task"] = "yes_no";
  j["blocks"] = Json::parse(R"([{"name": "a", "factors": {"section": [1, 2]}, "sides": {"object": "measured"}},
                                {"name": "b", "task": "rating", "factors": {"blur": [{"object": "none"},
                                                                                      {"object": 2.5}]}}])");
  return j;
}

TEST(ProtocolValidate, SingleLayoutShowsOneObjectAnsweredYesNoOrRated) {
  EXPECT_TRUE(Problems(Single()).empty()) << Problems(Single()).front();
  const Protocol p = ParseProtocol(Single(), SceneFolder() / "p.json");
  EXPECT_EQ(p.blocks[0].task, Task::kYesNo);
  EXPECT_EQ(p.blocks[1].task, Task::kRating);
  EXPECT_EQ(p.responses.yes, "Y");
  EXPECT_EQ(p.responses.rating.size(), 5u);
  Json bad = Single();
  bad["task"] = "forced_choice";
  ExpectProblem(bad, "/task: must be yes_no or rating for the layout single");
  bad = Single();
  bad["blocks"][0]["sides"] = {{"left", "measured"}, {"right", "none"}};
  ExpectProblem(bad, "/blocks/0/sides: the layout single shows one object");
  bad = Single();
  bad["blocks"][0]["sides"] = {{"object", "measured"}, {"left", "none"}};
  ExpectProblem(bad, "/blocks/0/sides/left: unknown key (known: object)");
  bad = Single();
  bad["counterbalance"] = "swap_copies";
  ExpectProblem(bad, "/counterbalance: must be none for the layout single");
  bad = Single();
  bad["blocks"][0].erase("sides");
  ExpectProblem(bad, "/blocks/0: needs the object shown");
  bad = Single();
  bad["blocks"][1]["factors"]["blur"][1] = {{"object", 2.5}, {"left", "none"}};
  ExpectProblem(bad, "/blocks/1/factors/blur/1: has an \"object\" (layout single) and left/right");
  bad = Single();
  bad["blocks"][1]["factors"]["blur"][1]["object"] = -1;
  ExpectProblem(bad, "/blocks/1/factors/blur/1/object: a blur source must be");
  // The pair layouts refuse "object" and one-object tasks.
  bad = Valid();
  bad["blocks"][0]["factors"]["pattern"][0] = {{"id", 1}, {"speed_cm_s", 3}, {"object", "none"}};
  bad["blocks"][0]["factors"]["pattern"][1] = {{"id", 2}, {"speed_cm_s", 3}, {"object", "none"}};
  ExpectProblem(bad, "\"object\" is for the layout single");
  bad = Valid();
  bad["blocks"][1]["task"] = "rating";
  ExpectProblem(bad, "/blocks/1/task: is for the layout single");
}

TEST(ProtocolValidate, ResponseKeysOfYesNoAndRating) {
  Json j = Single();
  j["responses"] = {{"yes", "J"}, {"no", "F"}, {"rating", {"1", "2", "3", "4", "5", "6", "7"}}};
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  EXPECT_EQ(p.responses.yes, "J");
  EXPECT_EQ(p.responses.rating.back(), "7");
  j["responses"] = {{"yes", "J"}, {"no", "J"}};
  ExpectProblem(j, "/responses/no: is the same key as /responses/yes");
  j["responses"] = {{"rating", {"1"}}};
  ExpectProblem(j, "/responses/rating: must be a list of 2 to 9 key names, got [\"1\"]");
  j["responses"] = {{"rating", {"1", "1"}}};
  ExpectProblem(j, "/responses/rating/1: is the same key as /responses/rating/0");
  j["responses"] = {{"rating", {"1", "Escape"}}};
  ExpectProblem(j, "/responses/rating/1: Escape is reserved");
  j["responses"] = {{"rating", {"1", 2}}};
  ExpectProblem(j, "/responses/rating/1: must be a key name, got 2");
  Json pair = Valid();
  pair["responses"] = {{"yes", "Y"}};
  ExpectProblem(pair, "/responses/yes: is for the task yes_no, which no block has");
  pair["responses"] = {{"alternatives", {"1", "2", "3"}}};
  ExpectProblem(pair, "/responses/alternatives: is for the layout odd_one_out");
  pair["responses"] = {{"accept", "Return"}};  // a pair protocol reads no stepping key
  ExpectProblem(pair, "/responses/accept: is for the task adjustment, which no block has");
}

TEST(ProtocolValidate, PromptAndAnsweringAfterTheMotion) {
  Json j = Valid();
  j["responses"] = {{"prompt", "Which ball is more blurred?"}, {"after_motion", true}};
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  EXPECT_EQ(p.responses.prompt, "Which ball is more blurred?");
  EXPECT_TRUE(p.responses.after_motion);
  j["responses"]["prompt"] = std::string(201, 'x');
  ExpectProblem(j, "/responses/prompt:");
  j["responses"]["prompt"] = "";
  ExpectProblem(j, "/responses/prompt:");
  j["responses"]["prompt"] = "ok";
  j["responses"]["after_motion"] = "yes";
  ExpectProblem(j, "/responses/after_motion:");
  // Nothing moves: nothing to wait for.
  Json still = Single();
  still["responses"] = {{"after_motion", true}};
  ExpectProblem(still, "/responses/after_motion: no block moves its objects");
}

// Odd one out: `alternatives` intervals (3 by default), named by their keys; QUEST+ guesses 1/n.
Json OddOneOut() {
  Json j = Valid();
  j["layout"] = "odd_one_out";
  j["blocks"] = Json::parse(R"([{"name": "a", "factors": {"section": [1, 2]},
                                 "sides": {"left": "measured", "right": "none"}}])");
  return j;
}

TEST(ProtocolValidate, OddOneOutHasAlternativesNamedByTheirKeys) {
  EXPECT_TRUE(Problems(OddOneOut()).empty()) << Problems(OddOneOut()).front();
  Protocol p = ParseProtocol(OddOneOut(), SceneFolder() / "p.json");
  EXPECT_EQ(p.alternatives, 3);
  EXPECT_EQ(IntervalCount(p), 3);
  EXPECT_EQ(p.responses.alternatives, (std::vector<std::string>{"1", "2", "3"}));
  EXPECT_TRUE(p.responses.cant_tell.empty());  // no "can't tell" unless a key is given for it
  Json j = OddOneOut();
  j["alternatives"] = 5;
  j["responses"] = {{"alternatives", {"A", "S", "D", "F", "G"}}};
  p = ParseProtocol(j, SceneFolder() / "p.json");
  EXPECT_EQ(IntervalCount(p), 5);
  EXPECT_EQ(p.responses.alternatives[4], "G");
  j["responses"] = {{"alternatives", {"A", "S", "D"}}};
  ExpectProblem(j, "/responses/alternatives: must be a list of 5 key names");
  j = OddOneOut();
  j["alternatives"] = 7;
  ExpectProblem(j, "/alternatives: must be an integer in [3, 6]");
  j["alternatives"] = 2.5;
  ExpectProblem(j, "/alternatives:");
  Json pair = Valid();
  pair["alternatives"] = 3;
  ExpectProblem(pair, "/alternatives: is for the layout odd_one_out");
  // A procedure's QUEST+ guesses right 1/n of the time: the default, and nothing else is accepted.
  j = OddOneOut();
  j.erase("counterbalance");
  j["blocks"] = Json::parse(R"([{"name": "q", "factors": {"section": [1]}, "procedure": {"type": "quest_plus",
      "variable": "relative_difference", "reference": "measured", "trials": 10, "stimuli": [0, 0.5, 1], "threshold": [0.2, 0.5], "slope": [2],
      "lapse": [0.02]}}])");
  p = ParseProtocol(j, SceneFolder() / "p.json");
  EXPECT_NEAR(p.blocks[0].procedure->guess, 1.0 / 3, 1e-12);
  j["blocks"][0]["procedure"]["guess"] = 0.5;
  ExpectProblem(j, "/blocks/0/procedure/guess: an odd-one-out trial of 3 intervals is guessed right 1/3");
}

// Every layout but side_by_side draws its objects at the left one's place, and intervals hold them still: a level
// placing the right object (right_x_mm), or ending a run in intervals (to_edge, to_y_mm), would be recorded on every
// row but not shown. Refused, naming the factor, the level object or the conditions table's row that gives it; the
// side-by-side pair reads them.
TEST(ProtocolValidate, PlaceALayoutDoesNotDrawIsRefused) {
  Json single = Single();
  single["blocks"][0]["factors"]["right_x_mm"] = {100};
  EXPECT_TRUE(Contains(OnlyProblem(single), "/blocks/0/factors/right_x_mm: the layout single shows every object at "
                                            "the left one's place (move it with left_x_mm): a right_x_mm level would "
                                            "be recorded but not shown, got [100]"))
      << OnlyProblem(single);
  single["blocks"][0]["factors"].erase("right_x_mm");
  single["blocks"][0]["factors"]["left_x_mm"] = {100};
  EXPECT_TRUE(Problems(single).empty()) << Problems(single).front();
  Json odd = OddOneOut();
  odd["blocks"][0]["factors"]["place"] = Json::parse(R"([{"left_x_mm": -30}, {"left_x_mm": -30, "right_x_mm": 120}])");
  EXPECT_TRUE(Contains(OnlyProblem(odd), "/blocks/0/factors/place/1/right_x_mm: the layout odd_one_out shows every "
                                         "object at the left one's place"))
      << OnlyProblem(odd);
  Json two = OddOneOut();
  two["layout"] = "two_intervals";
  two["blocks"][0]["factors"] = Json::parse(R"({"from_edge": [2], "to_edge": [9]})");
  EXPECT_TRUE(Contains(OnlyProblem(two), "/blocks/0/factors/to_edge: intervals show still objects, where a run would "
                                         "start: a to_edge level would be recorded but not shown, got [9]"))
      << OnlyProblem(two);
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "places.csv") << "edge,left_x_mm,right_x_mm\n3,-30,110\n5,-30,120\n";
  Json table = OddOneOut();
  table["content"] = {{"type", "grid"}};
  table["blocks"][0].erase("factors");
  table["blocks"][0]["conditions"] = "places.csv";
  EXPECT_TRUE(Contains(OnlyProblem(table), "places.csv line 2, column 3 (right_x_mm): the layout odd_one_out shows "
                                           "every object at the left one's place"))
      << OnlyProblem(table);
  // Side by side, the right object stands where right_x_mm puts it, and a rolling ball ends its run at to_edge.
  Json pair = Valid();
  pair["blocks"][1]["factors"] = Json::parse(R"({"pattern": [{"id": 2, "speed_cm_s": 1.8, "left": "measured",
                                                 "right": "none"}], "from_edge": [2], "to_edge": [9],
                                                 "right_x_mm": [120]})");
  EXPECT_TRUE(Problems(pair).empty()) << Problems(pair).front();
}

TEST(ProtocolValidate, AStaircaseStopRule) {
  Json j = Valid();
  j.erase("counterbalance");
  j["blocks"] = Json::parse(R"([{"name": "s", "factors": {"section": [1]}, "procedure": {"type": "staircase",
      "variable": "relative_difference", "reference": "measured", "trials": 20, "start": 1, "min": 0, "max": 2,
      "steps": [0.2], "stop": {"reversals": 8}}}])");
  EXPECT_EQ(ParseProtocol(j, SceneFolder() / "p.json").blocks[0].procedure->stop_reversals, 8);
  j["blocks"][0]["procedure"]["stop"]["reversals"] = 20;
  ExpectProblem(j, "/blocks/0/procedure/stop/reversals: can never be reached within 20 trials");
  j["blocks"][0]["procedure"]["stop"]["reversals"] = 0;
  ExpectProblem(j, "/blocks/0/procedure/stop/reversals: must be an integer in [1, 100]");
  j["blocks"][0]["procedure"]["stop"] = {{"trials", 3}};
  ExpectProblem(j, "/blocks/0/procedure/stop/trials: unknown key");
  j["blocks"][0]["procedure"]["stop"] = nullptr;
  ExpectProblem(j, "/blocks/0/procedure/stop:");
}

TEST(ProtocolValidate, PracticeUntilACriterion) {
  Json j = Valid();
  j["blocks"][0]["practice"] = true;
  j["blocks"][0]["criterion"] = {{"correct", 0.8}, {"max_repeats", 3}};
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  ASSERT_TRUE(p.blocks[0].criterion);
  EXPECT_DOUBLE_EQ(p.blocks[0].criterion->correct, 0.8);
  EXPECT_EQ(p.blocks[0].criterion->max_repeats, 3);
  EXPECT_EQ(SessionTrials(p), 3 * DesignTrials(p.blocks[0]) + DesignTrials(p.blocks[1]));
  Json bad = j;
  bad["blocks"][0]["practice"] = false;
  ExpectProblem(bad, "/blocks/0/criterion: is for a practice block");
  bad = j;
  bad["blocks"][0]["criterion"]["correct"] = 1.5;
  ExpectProblem(bad, "/blocks/0/criterion/correct: must be a number in [0.01, 1]");
  bad["blocks"][0]["criterion"]["correct"] = "nan";
  ExpectProblem(bad, "/blocks/0/criterion/correct:");
  bad = j;
  bad["blocks"][0]["criterion"]["max_repeats"] = 1;
  ExpectProblem(bad, "/blocks/0/criterion/max_repeats: must be an integer in [2, 20]");
  bad = j;
  bad["blocks"][0]["criterion"] = {{"correct", 0.8}};
  ExpectProblem(bad, "/blocks/0/criterion/max_repeats: is required");
  bad = j;
  bad["blocks"][0]["criterion"]["until"] = 3;
  ExpectProblem(bad, "/blocks/0/criterion/until: unknown key");
}

// Objects: a grid card of any size, cells, standing or lying, turned and raised; a ball raised; fields a content does
// not take are refused, and levels height_mm / rotation_deg place each trial.
TEST(ProtocolValidate, CardsAndBallsInAnyPose) {
  Json grid = Valid();
  grid["content"] = {{"type", "grid"}, {"size_mm", {80, 60}}, {"cells", 8}, {"pose", "standing"},
                     {"rotation_deg", 30}, {"height_mm", 12}};
  grid["blocks"] = Json::parse(R"([{"name": "a", "factors": {"edge": [2, 5], "rotation_deg": [-30, 0, 30],
                                    "height_mm": [0, 20]}, "sides": {"left": "measured", "right": "none"}}])");
  const Protocol p = ParseProtocol(grid, SceneFolder() / "p.json");
  EXPECT_EQ(p.content.size_mm, 80);
  EXPECT_EQ(p.content.card_height_mm, 60);
  EXPECT_EQ(p.content.cells, 8);
  EXPECT_TRUE(p.content.standing);
  EXPECT_EQ(p.content.rotation_deg, 30);
  EXPECT_EQ(p.content.height_mm, 12);
  Json bad = grid;
  bad["content"]["size_mm"] = 4;
  ExpectProblem(bad, "/content/size_mm: must be the card's side in [5, 500] mm or [width, height]");
  bad["content"]["size_mm"] = {80, "x"};
  ExpectProblem(bad, "/content/size_mm:");
  bad = grid;
  bad["content"]["cells"] = 21;
  ExpectProblem(bad, "/content/cells: must be an integer in [1, 20]");
  bad = grid;
  bad["content"]["pose"] = "hanging";
  ExpectProblem(bad, "/content/pose: must be one of");
  bad = grid;
  bad["content"]["rotation_deg"] = 1e308;
  ExpectProblem(bad, "/content/rotation_deg:");
  bad = grid;
  bad["content"]["radius_mm"] = 10;
  ExpectProblem(bad, "/content/radius_mm: unknown key");
  bad = grid;
  bad["blocks"][0]["factors"]["height_mm"] = {-1, 20};
  ExpectProblem(bad, "/blocks/0/factors/height_mm/0: a height above the table must be a number in [0, 1000] mm");
  bad = grid;
  bad["content"]["texture"] = "scene/scene.png";
  ExpectProblem(bad, "/content/cells: draws the grid card; an image texture has no cells");
  // A ball takes a height but no card's pose, and no turn per trial.
  Json ball = Valid();
  ball["content"]["height_mm"] = 5;
  EXPECT_EQ(ParseProtocol(ball, SceneFolder() / "p.json").content.height_mm, 5);
  ball["content"]["pose"] = "standing";
  ExpectProblem(ball, "/content/pose: unknown key");
  ball = Valid();
  ball["blocks"][1]["factors"]["rotation_deg"] = {0, 30};
  ExpectProblem(ball, "a ball does not use rotation_deg");
}


// Tables as spreadsheets save them (issue 24): CRLF and a lone CR end lines alike, a quoted field may hold a comma,
// and text after a closing quote ("ne"ar) is refused where it is instead of read as near.
TEST(ProtocolValidate, ConditionsTableReadAsSpreadsheetsWriteIt) {
  const fs::path dir = SceneFolder();
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "sheet.csv"}}};
  for (const char* text : {"edge,left,right,label\r\n1,measured,none,\"a, b\"\r\n2,none,measured,c\r\n",
                           "edge,left,right,label\r1,measured,none,\"a, b\"\r2,none,measured,c\r"}) {
    std::ofstream(dir / "sheet.csv", std::ios::binary) << text;
    const Protocol p = ParseProtocol(j, dir / "p.json");
    ASSERT_EQ(p.blocks[0].factors[0].levels.size(), 2u) << text;
    EXPECT_EQ(ToJson(p.blocks[0].factors[0].levels[0])["label"], "a, b");
    EXPECT_EQ(ToJson(p.blocks[0].factors[0].levels[1])["edge"], 2);
  }
  std::ofstream(dir / "sheet.csv", std::ios::binary) << "edge,left,right\n1,\"mea\"sured,none\n";
  EXPECT_TRUE(Contains(OnlyProblem(j), "sheet.csv line 2, column 8: text after a field's closing quote")) << OnlyProblem(j);
  // A line break inside quotes is part of the field: the problem names the row's own line, not a row that is not.
  std::ofstream(dir / "sheet.csv", std::ios::binary) << "edge,left,right,label\n1,measured,none,\"two\nlines\"\n";
  EXPECT_TRUE(Contains(OnlyProblem(j), (dir / "sheet.csv").string() + " line 2, column 4 (label): "
                                       "must be printable UTF-8 text on one line")) << OnlyProblem(j);
}

// A table a spreadsheet wrote with another list separator (';' from a German Excel, or tabs) says so; it was
// refused as one misspelt column, "to record it as a label nobody reads, name it label_edge;left;right". A column
// named twice is named once in the message (it read 'got "label", got "sheet.csv"').
TEST(ProtocolValidate, ConditionsTableWithAnotherSeparatorSaysSo) {
  const fs::path dir = SceneFolder();
  const std::string table = (dir / "sheet.csv").string();
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "sheet.csv"}}};
  std::ofstream(dir / "sheet.csv", std::ios::binary) << "edge;left;right\r\n1;measured;none\r\n";
  EXPECT_EQ(OnlyProblem(j), (dir / "p.json").string() + ": /blocks/0/conditions: " + table + " line 1: has one "
            "column, 'edge;left;right'; the columns of a conditions table are separated by commas, and this one uses "
            "';' (save it as CSV with commas), got \"sheet.csv\"");
  std::ofstream(dir / "sheet.csv", std::ios::binary) << "edge\tleft\tright\n1\tmeasured\tnone\n";
  EXPECT_TRUE(Contains(OnlyProblem(j), table + " line 1: has one column, 'edge\\tleft\\tright'; the columns of a "
                                       "conditions table are separated by commas, and this one uses tabs"))
      << OnlyProblem(j);
  std::ofstream(dir / "sheet.csv", std::ios::binary) << "edge,left,right,label,label\n1,measured,none,a,b\n";
  EXPECT_EQ(OnlyProblem(j), (dir / "p.json").string() + ": /blocks/0/conditions: " + table + " line 1, column 5 "
            "('label'): the header must name each column once, 1-100 characters, got \"sheet.csv\"");
}

// A label's cell stays the text it is: 007 and 7 are two ids, and a 16-digit id keeps its last digit. A number in a
// column that reads one must be held exactly, or it is refused naming what it would have become.
TEST(ProtocolValidate, ConditionsCellsKeepTheirTextAndNumbersTheirDigits) {
  const fs::path dir = SceneFolder();
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "cells.csv"}}};
  std::ofstream(dir / "cells.csv") << "edge,left,right,label_stim\n1,measured,none,007\n2,measured,none,7\n"
                                  "3,measured,none,9007199254740993\n";
  const Protocol p = ParseProtocol(j, dir / "p.json");
  const auto& levels = p.blocks[0].factors[0].levels;
  ASSERT_EQ(levels.size(), 3u);
  EXPECT_EQ(ToJson(levels[0])["label_stim"], "007");
  EXPECT_EQ(ToJson(levels[1])["label_stim"], "7");
  EXPECT_EQ(ToJson(levels[2])["label_stim"], "9007199254740993");
  std::ofstream(dir / "cells.csv") << "edge,left,right,y_mm\n1,measured,none,0.12345678901234567\n";
  EXPECT_TRUE(Contains(OnlyProblem(j), "cells.csv line 2, column 4 (y_mm): has more digits than a number holds exactly (it would be "
                                       "recorded as 0.12345678901234566)")) << OnlyProblem(j);
  std::ofstream(dir / "cells.csv") << "edge,left,right,y_mm\n1,measured,none,0.1\n2,measured,none,-2.50e1\n";
  EXPECT_EQ(ToJson(ParseProtocol(j, dir / "p.json").blocks[0].factors[0].levels[1])["y_mm"], -25.0);
}

// An id a spreadsheet would run as a formula, or that a bidirectional control shows reversed, is refused; a name of
// 100 characters fits however many bytes they take.
TEST(ProtocolValidate, IdsAndNamesAreSafeToOpenAndCountCharacters) {
  const fs::path dir = SceneFolder();
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "ids.csv"}}};
  std::ofstream(dir / "ids.csv") << "edge,left,right,id\n1,measured,none,=cmd|' /C calc'!A0\n";
  EXPECT_TRUE(Contains(OnlyProblem(j), "ids.csv line 2, column 4 (id): an id begins with =, which a spreadsheet opening the exported "
                                       "tables runs as a formula")) << OnlyProblem(j);
  j = Valid();
  j["name"] = "study\u202Eevil";
  EXPECT_TRUE(Contains(OnlyProblem(j), "/name: holds the bidirectional control character U+202E")) << OnlyProblem(j);
  std::string e100;
  for (int i = 0; i < 100; ++i) e100 += "\u00e9";
  j["name"] = e100;
  EXPECT_EQ(ParseProtocol(j, dir / "p.json").name, e100);
  EXPECT_THROW(CheckParticipantId("@P1"), Error);
  EXPECT_THROW(CheckParticipantId("P\u200F1"), Error);
  EXPECT_NO_THROW(CheckParticipantId("P-1"));
}

// A table too large is said in a table's words, not a JSON file's.
TEST(ProtocolValidate, ConditionsTableTooLargeSaysSo) {
  const fs::path dir = SceneFolder();
  { std::ofstream(dir / "big.csv") << "edge\n1\n"; }
  fs::resize_file(dir / "big.csv", 17u << 20);
  Json j = Valid();
  j["blocks"] = {{{"name", "rows"}, {"conditions", "big.csv"}}};
  EXPECT_TRUE(Contains(OnlyProblem(j), "a conditions table may have at most 16 MiB")) << OnlyProblem(j);
}

}  // namespace
}  // namespace blurcue::protocol
