#pragma once
// Where a side's blur comes from: one vocabulary for the protocol that names it, the calibration that evaluates it, the
// stimulus that plans it and the record that keeps it. It lives in core because calib (which knows nothing of
// protocols) and protocol (which knows nothing of calib) both read it; protocol/vocabulary.h lists it among the
// protocol's vocabularies.
#include <array>
#include <string>
#include <vector>

namespace blurcue {

// "none" | "measured" (the thesis's edge value) | "measured_section" (the nearest section alone) | "estimated"
// (eq. 3.7) | "fitted" (the thin-lens model) | "fixed" (a radius given as a number, never as this word).
enum class BlurSource { kNone, kMeasured, kMeasuredSection, kEstimated, kFitted, kFixed };

// Every value, in the order messages list them.
inline constexpr std::array kBlurSources{BlurSource::kNone,      BlurSource::kMeasured, BlurSource::kMeasuredSection,
                                         BlurSource::kEstimated, BlurSource::kFitted,   BlurSource::kFixed};

// The word for a source, as protocol files, commands, the record and messages spell it ("" outside the enum).
std::string ToString(BlurSource value);

// The words a protocol or a command may write for a source (every one but "fixed", which a number stands for), in
// kBlurSources order: the allowed values of a message and the candidates of its did-you-mean.
std::vector<std::string> BlurSourceWords();

}  // namespace blurcue
