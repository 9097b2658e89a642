#include "core/blur_source.h"

namespace blurcue {

// The switch lists every value and has no default: -Wswitch names it when a value is added.
std::string ToString(BlurSource value) {
  switch (value) {
    case BlurSource::kNone: return "none";
    case BlurSource::kMeasured: return "measured";
    case BlurSource::kMeasuredSection: return "measured_section";
    case BlurSource::kEstimated: return "estimated";
    case BlurSource::kFitted: return "fitted";
    case BlurSource::kFixed: return "fixed";
  }
  return "";
}

std::vector<std::string> BlurSourceWords() {
  std::vector<std::string> words;
  for (const BlurSource source : kBlurSources)
    if (source != BlurSource::kFixed) words.push_back(ToString(source));
  return words;
}

}  // namespace blurcue
