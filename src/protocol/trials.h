#pragma once
// The whole trial list of one session, made up front from a validated Protocol, a participant and a seed.
// Reproducible on every standard library: the only randomness is raw std::mt19937_64 output (its sequence is fixed
// by the C++ standard) turned into indices by our own rejection sampling and Fisher-Yates, never by
// std::shuffle or std::uniform_int_distribution, whose results differ between libraries.
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/hash.h"
#include "protocol/level.h"
#include "protocol/protocol.h"

namespace blurcue::protocol {

struct Trial {
  int index = 0;             // 0-based position in the session, practice trials included
  std::string block;
  bool practice = false;
  Task task = Task::kForcedChoice;
  int repetition = 0;        // 0-based copy of the design within the block
  int round = -1;            // a practice block with a criterion: which run of its design (0-based); -1 otherwise
  bool swapped = false;      // left and right exchanged against the design (counterbalancing)
  std::vector<Level> levels;  // one per factor of its block, in name order, as designed (not swapped)
  // The blur shown on each side (the single layout's object on both); none when the block shows no pair.
  std::optional<BlurSpec> left, right;
  // Adjustment only: the levels in the order the participant steps through them, and where stepping starts.
  std::vector<double> adjust_levels;
  int start_index = -1;
  // A procedure block's trial: which crossing of the block's factors (whose own procedure it feeds; -1 otherwise)
  // and the side that shows the procedure's level (a Side's word, drawn with the seed; TestSide reads it). In the
  // odd_one_out layout every trial's test_side is the interval ("1".."n", drawn with the seed; TestInterval) that shows
  // the right side's object (and a procedure's level): the correct answer.
  int cell = -1;
  std::string test_side;
};

// Uniform integer in [0, n) from raw generator output by rejection (no modulo bias); n >= 1.
uint64_t UniformBelow(std::mt19937_64& rng, uint64_t n);

// Fisher-Yates: for i = n-1 down to 1, swap element i with element UniformBelow(rng, i + 1).
template <typename T>
void Shuffle(std::vector<T>& items, std::mt19937_64& rng) {
  for (size_t i = items.size(); i > 1; --i) {
    const size_t j = static_cast<size_t>(UniformBelow(rng, i));
    if (j != i - 1) std::swap(items[i - 1], items[j]);
  }
}

// A participant id as the record, the exported tables and the report hold it (core/typed.h ParticipantIdProblem).
// Throws Error(kUsage) naming the id otherwise. BuildTrials checks it; RunSession checks it before it opens the
// record.
void CheckParticipantId(const std::string& participant);

// The participant's number: the trailing digits of the id ("P7" -> 7); -1 when it has none.
int ParticipantNumber(const std::string& participant);

// The order a participant runs the blocks in (indices into protocol.blocks): the practice blocks first, in file
// order, under every block_order; then the scored blocks in file order, in the order a seeded shuffle of all n
// blocks gives them (the generator's first draws: Fisher-Yates over n, as before practice was lifted out), or in
// row (participant number mod m, or mod 2m for an odd m) of a Williams balanced Latin square over the m scored
// blocks. Throws Error(kInput) for latin_square over two or more scored blocks with a participant id without number.
std::vector<size_t> BlockOrder(const Protocol& protocol, const std::string& participant, std::mt19937_64& rng);

// The protocol's practice trials first, then the blocks in BlockOrder (practice blocks, then the scored blocks in
// file order unless block_order says otherwise). Per block: the full factorial crossing of its factors
// (factors in name order, the last varying fastest) x repetitions; with swap_copies each trial also appears with
// left and right exchanged, with by_participant an even participant number sees every trial swapped; then the
// block is shuffled (unless "shuffle": false). One generator seeded with `seed` is drawn from in this order:
// the practice draw (a shuffled copy of the practice block's design, first `count` taken), each practice trial's
// adjustment draws, then per block its shuffle and each of its trials' adjustment draws in trial order (a shuffle
// of the levels when the order is "shuffled", then the start index) or, in a procedure block (procedure.trials
// copies of each crossing, the reference on both sides), its test side (odd_one_out: every forced-choice trial's odd interval instead). The order depends on the seed alone; give
// each participant their own seed. Throws Error(kInput) for by_participant with a participant id without number.
// With groups, only the blocks of `group` (protocol.groups; a block without "groups" runs for every group).
std::vector<Trial> BuildTrials(const Protocol& protocol, const std::string& participant, uint64_t seed,
                               const std::string& group = "");

// The group a new session of `participant` runs: by_number - names[(number - 1) mod n] (Error(kInput) for an id
// without number); balanced - the group with the fewest participants so far (`sessions`: group -> count; the first
// of equals). "" when the protocol has no groups.
std::string AssignGroup(const Protocol& protocol, const std::string& participant,
                        const std::map<std::string, int64_t>& sessions);

// The block `trial` belongs to (null for a trial made from another protocol).
const Block* BlockOf(const Protocol& protocol, const Trial& trial);
// Its place in protocol.blocks (0 when no block has the trial's name, as for a trial made by hand).
int BlockIndex(const Protocol& protocol, const Trial& trial);
// What `trial` reads of its block (Block::timing, Block::prompt); the protocol's own for a trial of no block.
const Timing& TimingOf(const Protocol& protocol, const Trial& trial);
const std::string& PromptOf(const Protocol& protocol, const Trial& trial);
// The title of the screen that opens the part trials[index] belongs to, never a block's name: "Practice" for
// practice drawn from a main block (protocol.practice); else the block's title; else "Practice" for a practice
// block, or "Part n of N" - n the place of the trial's block among the scored blocks of `trials` in the order the
// participant runs them, N their count.
std::string BlockTitle(const Protocol& protocol, const std::vector<Trial>& trials, size_t index);

// The JSON pointer of the field that chose what `trial` shows on `side` (as shown, swaps applied): the side of a
// level object (/blocks/1/factors/pattern/2/left) or of the block's sides (/sides/left).
std::string SidePointer(const Protocol& protocol, const Trial& trial, Side side);
// The side a procedure's trial shows its level on; nullopt for any other trial (an odd one out's is an interval).
std::optional<Side> TestSide(const Trial& trial);
// The interval (1..n) that shows an odd-one-out trial's odd object; 0 for any other trial.
int TestInterval(const Trial& trial);
// The JSON pointer of the level `name` of `trial` (/factors/edge/3, /blocks/0/factors/pattern/1/speed_cm_s), or
// of its block's factors when no level has that name.
std::string LevelPointer(const Protocol& protocol, const Trial& trial, const std::string& name);

Json ToJson(const Trial& trial);
Json ToJson(const std::vector<Trial>& trials);

// FNV-1a 64 of ToJson(trials).dump(): one number that changes when anything in the list changes.
uint64_t TrialsHash(const std::vector<Trial>& trials);

// The seed a participant gets when none is given: FNV-1a 64 of "STUDY/PARTICIPANT" (own per participant, recorded
// with the session like any other seed).
uint64_t DefaultSeed(const std::string& study, const std::string& participant);

}  // namespace blurcue::protocol
