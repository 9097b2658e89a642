#include "protocol/trials.h"

#include "core/hash.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "core/error.h"
#include "core/typed.h"

namespace blurcue::protocol {

uint64_t UniformBelow(std::mt19937_64& rng, uint64_t n) {
  // Reject the lowest 2^64 mod n outputs: the rest is a whole multiple of n, so every residue is equally likely.
  const uint64_t threshold = (0 - n) % n;  // == 2^64 mod n in unsigned arithmetic
  for (;;) {
    const uint64_t x = rng();
    if (x >= threshold) return x % n;
  }
}

void CheckParticipantId(const std::string& participant) {
  const std::string why = ParticipantIdProblem(participant);
  if (why.empty()) return;
  // The id as JSON text: control characters escaped, broken bytes replaced, cut short - one line whatever it held.
  std::string shown = Json(participant.substr(0, 40)).dump(-1, ' ', false, Json::error_handler_t::replace);
  if (participant.size() > 40) shown.insert(shown.size() - 1, "...");
  throw Error(ErrorKind::kUsage, "--participant " + why + ", got " + shown);
}

int ParticipantNumber(const std::string& participant) {
  size_t start = participant.size();
  while (start > 0 && std::isdigit(static_cast<unsigned char>(participant[start - 1]))) --start;
  if (start == participant.size() || participant.size() - start > 9) return -1;
  return std::stoi(participant.substr(start));
}

namespace {

// The sides a design row shows: from the level object that carries left/right, else the block's "sides". The
// single layout's one "object" is shown as the left side (and recorded on both).
void SetSides(const Block& block, Trial* t) {
  auto side = [](const Level& from, const std::string& key) -> std::optional<BlurSpec> {
    const LevelValue* v = from.Field("object") ? from.Field("object") : from.Field(key);
    if (!v) return std::nullopt;
    return BlurSpecOf(ToJson(*v));
  };
  for (const Level& level : t->levels)
    if (level.Field(ToString(Side::kLeft)) || level.Field("object")) {
      t->left = side(level, ToString(Side::kLeft));
      t->right = side(level, ToString(Side::kRight));
      return;
    }
  if (block.sides) {
    t->left = block.sides->left;
    t->right = block.sides->right;
  }
}

// The trial's level of factor `name`, or null.
const Level* LevelOf(const Trial& trial, const std::string& name) {
  for (const Level& level : trial.levels)
    if (level.factor == name) return &level;
  return nullptr;
}

// Full factorial x repetitions x counterbalancing, unshuffled.
std::vector<Trial> Design(const Block& block, bool participant_even) {
  std::vector<Trial> rows;
  size_t combinations = 1;
  for (const auto& f : block.factors) combinations *= f.levels.size();
  if (block.factors.empty()) combinations = 0;
  const int copies = block.procedure ? block.procedure->trials : block.repetitions;
  for (int rep = 0; rep < copies; ++rep) {
    for (size_t c = 0; c < combinations; ++c) {
      Trial t;
      t.block = block.name;
      t.task = block.task;
      t.repetition = rep;
      if (block.procedure) t.cell = static_cast<int>(c);
      // Mixed radix with the last factor fastest; the levels in name order (the factors are).
      t.levels.resize(block.factors.size());
      size_t rest = c;
      for (size_t k = block.factors.size(); k-- > 0;) {
        const auto& f = block.factors[k];
        t.levels[k] = f.levels[rest % f.levels.size()];
        rest /= f.levels.size();
      }
      SetSides(block, &t);
      if (block.procedure) t.left = t.right = block.procedure->reference;
      if (block.counterbalance == Counterbalance::kByParticipant && participant_even) {
        std::swap(t.left, t.right);
        t.swapped = true;
      }
      rows.push_back(t);
      if (block.counterbalance == Counterbalance::kSwapCopies) {
        std::swap(t.left, t.right);
        t.swapped = true;
        rows.push_back(std::move(t));
      }
    }
  }
  return rows;
}

void DrawAdjustment(const Block& block, int alternatives, std::mt19937_64& rng, Trial* t) {
  if (alternatives > 0 && TraitsOf(block.task).answer == TaskAnswer::kSide) {
    t->test_side = std::to_string(1 + UniformBelow(rng, uint64_t(alternatives)));
    return;
  }
  if (block.procedure) {
    t->test_side = ToString(UniformBelow(rng, 2) == 0 ? Side::kLeft : Side::kRight);
    return;
  }
  if (TraitsOf(block.task).answer != TaskAnswer::kLevel || !block.adjust) return;
  t->adjust_levels = block.adjust->levels;
  switch (block.adjust->order) {
    case AdjustOrder::kShuffled: Shuffle(t->adjust_levels, rng); break;
    case AdjustOrder::kAscending: std::sort(t->adjust_levels.begin(), t->adjust_levels.end()); break;
    case AdjustOrder::kDescending: std::sort(t->adjust_levels.rbegin(), t->adjust_levels.rend()); break;
  }
  t->start_index = static_cast<int>(UniformBelow(rng, t->adjust_levels.size()));
}

}  // namespace

std::string AssignGroup(const Protocol& protocol, const std::string& participant,
                        const std::map<std::string, int64_t>& sessions) {
  if (!protocol.groups || protocol.groups->names.empty()) return "";
  const auto& names = protocol.groups->names;
  if (protocol.groups->assign == GroupAssign::kBalanced) {
    std::string best = names.front();
    int64_t fewest = INT64_MAX;
    for (const auto& name : names) {
      const auto it = sessions.find(name);
      const int64_t n = it == sessions.end() ? 0 : it->second;
      if (n < fewest) fewest = n, best = name;
    }
    return best;
  }
  const int number = ParticipantNumber(participant);
  if (number < 0)
    throw InputError(protocol.file.string() + ": /groups/assign",
                     "by_number needs a participant id ending in a number (e.g. P7), got \"" + participant + "\"");
  return names[size_t((number + int(names.size()) - 1) % int(names.size()))];
}

std::vector<Trial> BuildTrials(const Protocol& protocol, const std::string& participant, uint64_t seed,
                               const std::string& group) {
  CheckParticipantId(participant);
  const Block* by_participant = nullptr;
  for (const auto& b : protocol.blocks)
    if (!by_participant && b.counterbalance == Counterbalance::kByParticipant) by_participant = &b;
  const int number = ParticipantNumber(participant);
  if (by_participant && number < 0)
    throw InputError(protocol.file.string() + ": " + by_participant->counterbalance_pointer, "by_participant counterbalancing needs a participant id ending in a "
                                             "number (e.g. P7), got \"" + participant + "\"");
  const bool even = number >= 0 && number % 2 == 0;
  // ParseProtocol refuses such designs; a Protocol made otherwise is refused here, before anything is allocated.
  if (const int64_t n = SessionTrials(protocol); n > kMaxTrials || n == 0)
    throw InputError(protocol.file.string(), n == 0 ? "/: the protocol makes no trials"
                                                    : "/: the protocol makes more than " + std::to_string(kMaxTrials) +
                                                          " trials, the most a session may have");

  std::mt19937_64 rng(seed);
  const std::vector<size_t> order = BlockOrder(protocol, participant, rng);
  std::vector<Trial> trials;
  if (protocol.practice.count > 0) {
    for (const auto& b : protocol.blocks) {
      if (b.name != protocol.practice.block) continue;
      std::vector<Trial> pool = Design(b, even);
      Shuffle(pool, rng);
      if (pool.size() > static_cast<size_t>(protocol.practice.count)) pool.resize(protocol.practice.count);
      for (auto& t : pool) {
        t.practice = true;
        DrawAdjustment(b, protocol.alternatives, rng, &t);
        trials.push_back(std::move(t));
      }
      break;
    }
  }
  for (const size_t k : order) {
    const Block& b = protocol.blocks[k];
    if (!group.empty() && !b.groups.empty() && std::find(b.groups.begin(), b.groups.end(), group) == b.groups.end())
      continue;  // another group's block
    // A practice block with a criterion runs its design up to max_repeats times, each round shuffled on its own.
    const int rounds = b.criterion ? b.criterion->max_repeats : 1;
    for (int round = 0; round < rounds; ++round) {
      std::vector<Trial> rows = Design(b, even);
      if (b.shuffle) Shuffle(rows, rng);
      for (auto& t : rows) {
        t.practice = b.practice;  // a practice block's trials are recorded as practice
        t.round = b.criterion ? round : -1;
        DrawAdjustment(b, protocol.alternatives, rng, &t);
        trials.push_back(std::move(t));
      }
    }
  }
  for (size_t i = 0; i < trials.size(); ++i) trials[i].index = static_cast<int>(i);
  return trials;
}

std::vector<size_t> BlockOrder(const Protocol& protocol, const std::string& participant, std::mt19937_64& rng) {
  const size_t n = protocol.blocks.size();
  std::vector<size_t> all(n);
  for (size_t i = 0; i < n; ++i) all[i] = i;
  // Practice comes first whatever the order, in the file's order; only the scored blocks are ordered. The random
  // order still shuffles every block (the same draws as before practice blocks were lifted out, so the generator
  // is where it was for everything drawn after) and keeps the scored blocks in the order that shuffle gives them.
  if (protocol.block_order == BlockSequence::kRandom) Shuffle(all, rng);
  std::vector<size_t> order, scored;
  for (size_t i = 0; i < n; ++i)
    if (protocol.blocks[i].practice) order.push_back(i);
  for (const size_t k : all)
    if (!protocol.blocks[k].practice) scored.push_back(k);
  const size_t m = scored.size();
  if (protocol.block_order == BlockSequence::kLatinSquare && m > 1) {
    const int number = ParticipantNumber(participant);
    if (number < 0)
      throw InputError(protocol.file.string() + ": /block_order",
                       "latin_square needs a participant id ending in a number (e.g. P7), got \"" + participant + "\"");
    // Williams over the scored blocks: 0, 1, m-1, 2, m-2, ... shifted by the row; an odd m needs the reversed rows too.
    const size_t rows = m % 2 == 0 ? m : 2 * m;
    const size_t row = size_t(number) % rows, shift = row % m;
    std::vector<size_t> square(m);
    for (size_t j = 0; j < m; ++j) {
      const size_t base = j % 2 == 1 ? (j + 1) / 2 : (m - j / 2) % m;
      square[j] = scored[(base + shift) % m];
    }
    if (row >= m) std::reverse(square.begin(), square.end());
    scored = square;
  }
  order.insert(order.end(), scored.begin(), scored.end());
  return order;
}

const Block* BlockOf(const Protocol& protocol, const Trial& trial) {
  for (const auto& b : protocol.blocks)
    if (b.name == trial.block) return &b;
  return nullptr;
}

const Timing& TimingOf(const Protocol& protocol, const Trial& trial) {
  const Block* block = BlockOf(protocol, trial);
  return block ? block->timing : protocol.timing;
}

const std::string& PromptOf(const Protocol& protocol, const Trial& trial) {
  const Block* block = BlockOf(protocol, trial);
  return block ? block->prompt : protocol.responses.prompt;
}

std::string BlockTitle(const Protocol& protocol, const std::vector<Trial>& trials, size_t index) {
  const Trial& trial = trials.at(index);
  const Block* block = BlockOf(protocol, trial);
  const bool practice_block = block && block->practice;
  if (trial.practice && !practice_block) return "Practice";
  if (block && !block->title.empty()) return block->title;
  if (trial.practice) return "Practice";
  // The participant's own count: the scored blocks this session runs (its group's), in the order it runs them. A
  // block's name is the experimenter's and may give the condition away ("rate-sharp"), so it is never shown.
  std::vector<std::string> scored;
  for (const Trial& t : trials)
    if (!t.practice && std::find(scored.begin(), scored.end(), t.block) == scored.end()) scored.push_back(t.block);
  const size_t n = size_t(std::find(scored.begin(), scored.end(), trial.block) - scored.begin()) + 1;
  return "Part " + std::to_string(n) + " of " + std::to_string(scored.size());
}

int BlockIndex(const Protocol& protocol, const Trial& trial) {
  const Block* block = BlockOf(protocol, trial);
  return block ? static_cast<int>(block - protocol.blocks.data()) : 0;
}

std::string SidePointer(const Protocol& protocol, const Trial& trial, Side side) {
  // A swapped trial shows the design's other side.
  const std::string designed = ToString(trial.swapped ? Other(side) : side);
  for (const auto& b : protocol.blocks) {
    if (b.name != trial.block) continue;
    for (const auto& f : b.factors) {
      const Level* level = LevelOf(trial, f.name);
      if (!level || !level->Field(designed)) continue;
      const auto at = std::find(f.levels.begin(), f.levels.end(), *level);
      return b.factors_pointer + "/" + JsonPointerToken(f.name) + "/" + std::to_string(at - f.levels.begin()) + "/" +
             designed;
    }
    if (!b.sides_pointer.empty()) return b.sides_pointer + "/" + designed;
    return b.pointer.empty() ? "/" : b.pointer;
  }
  return "/";
}

std::optional<Side> TestSide(const Trial& trial) { return ParseWord<Side>(trial.test_side); }

int TestInterval(const Trial& trial) {
  const std::string& s = trial.test_side;
  return !s.empty() && std::isdigit(static_cast<unsigned char>(s[0])) ? std::stoi(s) : 0;
}

std::string LevelPointer(const Protocol& protocol, const Trial& trial, const std::string& name) {
  for (const auto& b : protocol.blocks) {
    if (b.name != trial.block) continue;
    for (const auto& f : b.factors) {
      const Level* level = LevelOf(trial, f.name);
      if (!level || (f.name != name && !level->Field(name))) continue;
      const auto at = std::find(f.levels.begin(), f.levels.end(), *level);
      std::string pointer = b.factors_pointer + "/" + JsonPointerToken(f.name) + "/" +
                            std::to_string(at - f.levels.begin());
      if (f.name != name) pointer += "/" + JsonPointerToken(name);
      return pointer;
    }
    return b.factors_pointer.empty() ? "/" : b.factors_pointer;
  }
  return "/";
}

Json ToJson(const Trial& t) {
  Json j = {{"index", t.index},         {"block", t.block},     {"practice", t.practice},
            {"task", ToString(t.task)}, {"repetition", t.repetition}, {"swapped", t.swapped},
            {"levels", ToJson(t.levels)}, {ToString(Side::kLeft), ToJson(t.left)},
            {ToString(Side::kRight), ToJson(t.right)}};
  if (TraitsOf(t.task).answer == TaskAnswer::kLevel) {
    j["adjust_levels"] = t.adjust_levels;
    j["start_index"] = t.start_index;
  }
  if (t.cell >= 0) j["cell"] = t.cell;
  if (!t.test_side.empty()) j["test_side"] = t.test_side;  // a procedure's test side, an odd one out's interval
  if (t.round >= 0) j["round"] = t.round;
  return j;
}

Json ToJson(const std::vector<Trial>& trials) {
  Json j = Json::array();
  for (const auto& t : trials) j.push_back(ToJson(t));
  return j;
}

uint64_t TrialsHash(const std::vector<Trial>& trials) { return Fnv1a64(ToJson(trials).dump()); }

uint64_t DefaultSeed(const std::string& study, const std::string& participant) {
  return Fnv1a64(study + "/" + participant);
}


}  // namespace blurcue::protocol
