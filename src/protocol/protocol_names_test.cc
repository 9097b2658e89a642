// Every name an experimenter writes is checked against what blurcue reads, and a slip is answered with the name
// that was probably meant; what the participant sees of a block (title, prompt, timing) is the block's own.
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "protocol/protocol.h"
#include "protocol/protocol_test_util.h"
#include "protocol/trials.h"

namespace blurcue::protocol {
namespace {

using namespace test;  // NOLINT: the helpers every test here uses

// The problem line as validate prints it: the protocol file, the pointer, the message.
std::string Line(const std::string& pointer_and_message) {
  return (SceneFolder() / "p.json").string() + ": " + pointer_and_message;
}

// A level's value that is true or null - a pattern's side, its speed, a section - is refused naming the file and its
// field (a pattern's "right": true stopped validate with "a level must be a number or a string, got true", naming
// neither; found by the protocol fuzz).
TEST(ProtocolValidate, ALevelsTrueOrNullIsRefusedNamingItsField) {
  Json j = Valid();
  j["blocks"][0]["factors"]["pattern"][1]["right"] = true;
  EXPECT_TRUE(Contains(OnlyProblem(j), Line("/blocks/0/factors/pattern/1/right: ")));
  j = Valid();
  j["blocks"][0]["factors"]["pattern"][0]["speed_cm_s"] = nullptr;
  ExpectProblem(j, Line("/blocks/0/factors/pattern/0/speed_cm_s: "));
  j = Valid();
  j["blocks"][1]["factors"]["section"][0] = true;
  ExpectProblem(j, Line("/blocks/1/factors/section/0: "));
}

TEST(ProtocolValidate, MisspeltFactorIsRefusedWithDidYouMean) {
  Json j = Valid();
  j["blocks"][1]["factors"].erase("section");
  j["blocks"][1]["factors"]["secton"] = {1, 2};
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/1/factors/secton: no part of blurcue reads a factor secton (did you mean "
                                 "section?); to record it as a label nobody reads, name it label_secton"));
}

TEST(ProtocolValidate, FactorInTheWrongCaseIsRefusedWithDidYouMean) {
  Json j = Valid();
  j["content"] = {{"type", "grid"}};
  j["factors"] = {{"Edge", {3, 6}}};
  j["sides"] = {{"left", "measured"}, {"right", "estimated"}};
  j.erase("blocks");
  EXPECT_EQ(OnlyProblem(j), Line("/factors/Edge: no part of blurcue reads a factor Edge (did you mean edge?); to "
                                 "record it as a label nobody reads, name it label_Edge"));
}

TEST(ProtocolValidate, FactorFarFromAnyReadNameIsRefusedWithoutAGuess) {
  Json j = Valid();
  j["blocks"][1]["factors"]["colour"] = {1, 2};
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/1/factors/colour: no part of blurcue reads a factor colour; to record it "
                                 "as a label nobody reads, name it label_colour"));
}

TEST(ProtocolValidate, LabelsAreRecordedThoughNothingReadsThem) {
  Json j = Valid();
  j["blocks"][1]["factors"]["label_session"] = {"am", "pm"};
  j["blocks"][0]["factors"]["pattern"][0]["label"] = "slow-measured";
  j["blocks"][0]["factors"]["pattern"][1]["label_note"] = "second";
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
  // A factor whose levels are objects is named freely: its levels' keys are what is read.
  j["blocks"][0]["factors"]["my patterns"] = j["blocks"][0]["factors"]["pattern"];
  j["blocks"][0]["factors"].erase("pattern");
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
}

TEST(ProtocolValidate, LabelWithoutANameIsRefused) {
  Json j = Valid();
  j["blocks"][1]["factors"]["label_"] = {"am", "pm"};
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/1/factors/label_: a label needs a name after label_ (e.g. label_stim_id)"));
}

TEST(ProtocolValidate, MisspeltObjectLevelKeyIsRefusedOnceWithDidYouMean) {
  Json j = Valid();
  for (auto& level : j["blocks"][0]["factors"]["pattern"]) {
    level["speed_cms"] = level["speed_cm_s"];
    level.erase("speed_cm_s");
  }
  // Both levels have it: named once, at the first.
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/factors/pattern/0/speed_cms: no part of blurcue reads a level key "
                                 "speed_cms (did you mean speed_cm_s?); to record it as a label nobody reads, name it "
                                 "label_speed_cms"));
}

TEST(ProtocolValidate, MisspeltConditionsColumnIsRefusedNamingFileLineAndColumn) {
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "rows-names.csv") << "id,speed_cm_s,left,rigth\n1,3,measured,none\n2,1.8,estimated,none\n";
  Json j = Valid();
  j["blocks"][0].erase("factors");
  j["blocks"][0]["conditions"] = "rows-names.csv";
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/conditions: " + (dir / "rows-names.csv").string() +
                                 " line 1, column 4: no part of blurcue reads a column rigth (did you mean right?); "
                                 "to record it as a label nobody reads, name it label_rigth"));
  std::ofstream(dir / "rows-names.csv") << "id,speed_cm_s,left,right,label\n1,3,measured,none,slow\n";
  EXPECT_TRUE(Problems(j).empty()) << Problems(j).front();
}

// A name that becomes a column of the tables - a label factor's, an object-level factor's, a conditions table's
// column - or a value recorded as a name (a choice, recorded as info_KEY) is refused when it holds a bidirectional
// control, which shows it in another order than it is recorded, or begins as a spreadsheet formula (the adversary's
// label_U+202Ex and "=left" validated and reached trials.csv as they were).
TEST(ProtocolValidate, NamesThatReadBackwardsOrRunAsFormulasAreRefused) {
  const std::string rlo = "\xE2\x80\xAE";  // U+202E RIGHT-TO-LEFT OVERRIDE
  const std::string shown = "\\u202E";     // as a message quotes it (OneLine): a terminal line stays in order
  const std::string why = "holds the bidirectional control character U+202E, which shows the text to a reader in "
                          "another order than it is recorded";
  Json j = Valid();
  j["blocks"][1]["factors"]["label_" + rlo + "ab"] = {"x", "y"};
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/1/factors/label_" + rlo + "ab: the factor name 'label_" + shown + "ab' " + why));
  j = Valid();
  j["blocks"][0]["factors"]["pat" + rlo + "tern"] = j["blocks"][0]["factors"]["pattern"];
  j["blocks"][0]["factors"].erase("pattern");
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/factors/pat" + rlo + "tern: the factor name 'pat" + shown + "tern' " + why));
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "rows-bidi.csv") << "id,speed_cm_s,left,right,label_" << rlo << "x\n1,3,measured,none,a\n";
  j = Valid();
  j["blocks"][0].erase("factors");
  j["blocks"][0]["conditions"] = "rows-bidi.csv";
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/conditions: " + (dir / "rows-bidi.csv").string() + " line 1, column 5: "
                                 "the column name 'label_" + shown + "x' " + why));
  j = Valid();
  j["participant_info"] = {{{"key", "hand"}, {"type", "choice"}, {"choices", {"=left", "right"}}}};
  EXPECT_EQ(OnlyProblem(j), Line("/participant_info/0/choices/0: begins with =, which a spreadsheet opening the "
                                 "exported tables runs as a formula, got \"=left\""));
}

// A cell's problem is named where the cell is written: the table's file, line and column (by number and name), not
// a pointer into a JSON document the experimenter never wrote; and once, however many blocks use the table.
TEST(ProtocolValidate, ConditionsCellProblemNamesTheTablesLineAndColumn) {
  const fs::path dir = SceneFolder();
  std::ofstream(dir / "rows-cells.csv") << "id,speed_cm_s,left,right\n1,3,measured,none\n2,300,Measured,\n";
  Json j = Valid();
  j["blocks"][0].erase("factors");
  j["blocks"][0]["conditions"] = "rows-cells.csv";
  j["blocks"][1].erase("factors");
  j["blocks"][1]["conditions"] = "rows-cells.csv";
  const std::string table = (dir / "rows-cells.csv").string();
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0], Line(table + " line 3, column 2 (speed_cm_s): a speed must be a number in [0.1, 100] cm/s, "
                              "got 300"));
  EXPECT_TRUE(Contains(problems[1], table + " line 3, column 3 (left): a blur source must be ")) << problems[1];
  EXPECT_TRUE(Contains(problems[1], "(did you mean measured?), got \"Measured\"")) << problems[1];
  EXPECT_EQ(problems[2], Line(table + " line 3, column 4 (right): is empty, got \"\""));
}

TEST(ProtocolValidate, EnumValueMisspeltGetsDidYouMean) {
  Json j = Valid();
  j["counterbalance"] = "swap-copies";
  EXPECT_EQ(OnlyProblem(j), Line("/counterbalance: must be one of swap_copies | by_participant | none (did you mean "
                                 "swap_copies?), got \"swap-copies\""));
  j = Valid();
  j["content"]["kernel"] = "Disc";
  EXPECT_EQ(OnlyProblem(j), Line("/content/kernel: must be one of gaussian | disc (did you mean disc?), got \"Disc\""));
  j = Valid();
  j["block_order"] = "latin-square";
  EXPECT_EQ(OnlyProblem(j), Line("/block_order: must be one of fixed | random | latin_square (did you mean "
                                 "latin_square?), got \"latin-square\""));
  // Nothing near: the list alone.
  j["block_order"] = "shuffled";
  EXPECT_EQ(OnlyProblem(j), Line("/block_order: must be one of fixed | random | latin_square, got \"shuffled\""));
}

TEST(ProtocolValidate, ProcedureVariableMisspeltGetsDidYouMean) {
  Json j = Json::parse(R"({
    "name": "adaptive", "version": 1,
    "scene": {"background": "scene/scene.png", "calib": "calib.json"},
    "content": {"type": "grid"}, "task": "forced_choice",
    "blocks": [{"name": "stairs", "factors": {"edge": [3]},
                "procedure": {"type": "staircase", "variable": "difference_arcmins", "reference": "fitted",
                              "trials": 10, "start": 1, "min": 0.05, "max": 2, "steps": [0.4, 0.2]}}]
  })");
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/procedure/variable: must be one of relative_difference | "
                                 "difference_arcmin (did you mean difference_arcmin?), got \"difference_arcmins\""));
}

TEST(ProtocolValidate, BlurSourceAndTextureInTheWrongCaseGetDidYouMean) {
  Json j = Valid();
  j["blocks"][0]["factors"]["pattern"][0]["left"] = "Measured";
  EXPECT_TRUE(Contains(OnlyProblem(j), "/blocks/0/factors/pattern/0/left: a blur source must be none, measured, "))
      << OnlyProblem(j);
  EXPECT_TRUE(Contains(OnlyProblem(j), " (did you mean measured?), got \"Measured\"")) << OnlyProblem(j);
  j = Valid();
  j["content"]["texture"] = "Soccer";
  EXPECT_EQ(OnlyProblem(j), Line("/content/texture: must be soccer or wood or an image file (did you mean soccer?), "
                                 "got \"Soccer\""));
}

TEST(ProtocolValidate, BlockGroupAndPracticeBlockMisspeltGetDidYouMean) {
  Json j = Valid();
  j["groups"] = {{"names", {"estimated", "no_blur"}}};
  j["blocks"][0]["groups"] = {"estimatd"};
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/groups/0: names no group of /groups/names (did you mean estimated?), got "
                                 "\"estimatd\""));
  j = Valid();
  j["practice"] = {{"count", 2}, {"block", "tsk1"}};
  EXPECT_EQ(OnlyProblem(j), Line("/practice/block: names no block of this protocol (did you mean task1?), got "
                                 "\"tsk1\""));
}

// Groups or choices that differ only in letter case: a slip of one is answered with the other (did you mean), so
// they cannot be told apart; "a" and "A", "left" and "Left" used to pass.
TEST(ProtocolValidate, GroupsOrChoicesDifferingOnlyInCaseAreRefused) {
  Json j = Valid();
  j["groups"] = {{"names", {"near", "Near"}}};
  bool named = false;
  for (const std::string& p : Problems(j))
    named = named || Contains(p, "/groups/names/1: must differ from an earlier name by more than letter case, got "
                                 "\"Near\"");
  EXPECT_TRUE(named) << Problems(j).front();
  j = Valid();
  j["participant_info"] = {{{"key", "hand"}, {"type", "choice"}, {"choices", {"left", "right", "Left"}}}};
  EXPECT_EQ(OnlyProblem(j), Line("/participant_info/0/choices/2: must differ from an earlier answer by more than "
                                 "letter case, got \"Left\""));
}

TEST(ProtocolValidate, ResponseKeyInTheWrongCaseGetsDidYouMean) {
  Json j = Valid();
  j["responses"] = {{"left", "left"}, {"right", "q"}};
  const auto problems = Problems(j);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], Line("/responses/left: must be a key name: A-Z, 0-9, Left, Right, Up, Down, Space, Return, "
                              "Tab, Backspace, F1-F12 or KP_0-KP_9 (did you mean Left?), got \"left\""));
  EXPECT_TRUE(Contains(problems[1], "/responses/right: must be a key name: ")) << problems[1];
  EXPECT_TRUE(Contains(problems[1], " (did you mean Q?), got \"q\"")) << problems[1];
}

TEST(ParticipantInfo, ChoiceInTheWrongCaseGetsDidYouMean) {
  InfoField handedness;
  handedness.key = "handedness";
  handedness.type = InfoType::kChoice;
  handedness.choices = {"left", "right", "both"};
  EXPECT_EQ(CheckInfoValue(handedness, "Left"), "must be one of left, right, both (did you mean left?)");
  EXPECT_EQ(CheckInfoValue(handedness, "rigth"), "must be one of left, right, both (did you mean right?)");
  EXPECT_EQ(CheckInfoValue(handedness, "ambidextrous"), "must be one of left, right, both");
  EXPECT_EQ(CheckInfoValue(handedness, "left"), "");
}

// A block's timing is the protocol's with each field the block gives overriding it; its prompt the protocol's unless
// it gives its own; its title as given.
TEST(ProtocolParse, BlockTitlePromptAndTimingAreResolvedPerBlock) {
  Json j = Valid();
  j["timing"] = {{"inter_trial_ms", 800}, {"fixation_ms", 200}};
  j["responses"] = {{"prompt", "Which one is nearer?"}};
  j["blocks"][1]["title"] = "Second part";
  j["blocks"][1]["prompt"] = "Which ball looks nearer?";
  j["blocks"][1]["timing"] = {{"inter_trial_ms", 300}, {"stimulus_ms", 4000}};
  ASSERT_TRUE(Problems(j).empty()) << Problems(j).front();
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  EXPECT_EQ(p.blocks[0].title, "");
  EXPECT_EQ(p.blocks[1].title, "Second part");
  EXPECT_EQ(p.blocks[0].prompt, "Which one is nearer?");
  EXPECT_EQ(p.blocks[1].prompt, "Which ball looks nearer?");
  EXPECT_EQ(p.blocks[0].timing.inter_trial_ms, 800);
  EXPECT_EQ(p.blocks[0].timing.stimulus_ms, 0);
  EXPECT_EQ(p.blocks[1].timing.inter_trial_ms, 300);
  EXPECT_EQ(p.blocks[1].timing.stimulus_ms, 4000);
  EXPECT_EQ(p.blocks[1].timing.fixation_ms, 200);  // not given by the block: the protocol's
  // A file without blocks: its one block has the protocol's.
  Json one = Valid();
  one["factors"] = one["blocks"][0]["factors"];
  one.erase("blocks");
  one["timing"] = {{"inter_trial_ms", 700}};
  const Protocol q = ParseProtocol(one, SceneFolder() / "p.json");
  EXPECT_EQ(q.blocks.at(0).timing.inter_trial_ms, 700);
}

TEST(ProtocolValidate, BlockTitlePromptAndTimingAreChecked) {
  Json j = Valid();
  j["blocks"][0]["title"] = std::string(101, 'x');
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/title: must be at most 100 characters, got 101"));
  j["blocks"][0]["title"] = "two\nlines";
  EXPECT_TRUE(Contains(OnlyProblem(j), "/blocks/0/title: must not contain control characters")) << OnlyProblem(j);
  j["blocks"][0]["title"] = "";
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/title: must not be empty (leave it out for \"Part n of N\"), got \"\""));
  j["blocks"][0]["title"] = "   ";  // blank: no title on screen, accepted before
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/title: must not be empty (leave it out for \"Part n of N\"), got \"   \""));
  j = Valid();
  j["blocks"][0]["prompt"] = "";
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/prompt: must not be empty (leave it out for /responses/prompt), got \"\""));
  j["blocks"][0]["prompt"] = " ";
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/prompt: must not be empty (leave it out for /responses/prompt), got \" \""));
  j = Valid();
  j["blocks"][0]["timing"] = {{"fixaton_ms", 200}};
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/timing/fixaton_ms: unknown key (did you mean \"fixation_ms\"?), got 200"));
  j["blocks"][0]["timing"] = {{"fixation", 200}};  // a key without its unit: the one it abbreviates
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/timing/fixation: unknown key (did you mean \"fixation_ms\"?), got 200"));
  // A field checked against the block it is given for: this block has no correct answer to give feedback on.
  j["blocks"][0]["timing"] = {{"feedback_ms", 500}};
  EXPECT_EQ(OnlyProblem(j), Line("/blocks/0/timing/feedback_ms: needs a correct answer: a block with a procedure or a "
                                 "criterion, or the layout odd_one_out, defines one, got 500"));
  j["blocks"][0]["timing"] = {{"stimulus_ms", "until_responce"}};
  EXPECT_TRUE(Contains(OnlyProblem(j), "(did you mean until_response?), got \"until_responce\"")) << OnlyProblem(j);
}

// The screen that opens a part says "Part n of N" in the order this participant runs the scored blocks, "Practice"
// for practice, or the block's own title - never the block's name, which may give the condition away.
TEST(BlockScreen, TitleIsThePartNumberOrTheBlocksTitleNeverItsName) {
  Json j = Valid();
  j["blocks"][0]["name"] = "rate-sharp";
  j["blocks"][1]["name"] = "rate-blurred";
  j["blocks"].push_back({{"name", "warm-up-sharp"}, {"practice", true},
                         {"factors", {{"pattern", {j["blocks"][0]["factors"]["pattern"][0]}}}}});
  j["block_order"] = "latin_square";
  const Protocol p = ParseProtocol(j, SceneFolder() / "p.json");
  for (const char* participant : {"P1", "P2"}) {
    const auto trials = BuildTrials(p, participant, 7);
    std::vector<std::string> order;  // the scored blocks as this participant runs them
    for (size_t i = 0; i < trials.size(); ++i) {
      const std::string title = BlockTitle(p, trials, i);
      EXPECT_EQ(title.find("rate"), std::string::npos) << title;
      EXPECT_EQ(title.find("warm"), std::string::npos) << title;
      if (trials[i].practice) {
        EXPECT_EQ(title, "Practice");
        continue;
      }
      if (order.empty() || order.back() != trials[i].block) order.push_back(trials[i].block);
      EXPECT_EQ(title, "Part " + std::to_string(order.size()) + " of 2") << participant << " trial " << i;
    }
    EXPECT_EQ(order.size(), 2u);
  }
  // The two participants run the scored blocks in opposite orders: "Part 1" is a different block for each.
  const auto p1 = BuildTrials(p, "P1", 7), p2 = BuildTrials(p, "P2", 7);
  auto first_scored = [](const std::vector<Trial>& trials) {
    for (const auto& t : trials)
      if (!t.practice) return t.block;
    return std::string();
  };
  EXPECT_NE(first_scored(p1), first_scored(p2));
  // A title given is shown as it is, practice blocks included.
  j["blocks"][0]["title"] = "The slow balls";
  j["blocks"][2]["title"] = "Try it";
  const Protocol titled = ParseProtocol(j, SceneFolder() / "p.json");
  const auto trials = BuildTrials(titled, "P1", 7);
  for (size_t i = 0; i < trials.size(); ++i) {
    if (trials[i].block == "rate-sharp") {
      EXPECT_EQ(BlockTitle(titled, trials, i), "The slow balls");
    }
    if (trials[i].block == "warm-up-sharp") {
      EXPECT_EQ(BlockTitle(titled, trials, i), "Try it");
    }
  }
}

}  // namespace
}  // namespace blurcue::protocol
