// quest_trace IN.json: runs blurcue's QUEST+ (procedure/adaptive.h) on a scripted observer and prints what it chose.
// IN: {"stimuli": [...], "threshold": [...], "slope": [...], "lapse": [...], "guess": g,
//      "observer": {"threshold": t, "slope": b, "lapse": l}, "u": [u0, u1, ...]}
// Trial i shows the procedure's next stimulus x_i and is answered correctly when u_i < the observer's Weibull at
// x_i. OUT (stdout): {"stimuli": [x0, ...], "posterior": [...], "mean_threshold": m, "mean_slope": s}.
// tests/quest_agreement.py runs python3-questplus on the same and compares.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "core/json_io.h"
#include "procedure/adaptive.h"

int main(int argc, char** argv) {
  if (argc != 2) return std::fprintf(stderr, "usage: quest_trace IN.json\n"), 2;
  const blurcue::Json in = blurcue::ParseJson(blurcue::ReadTextFile(argv[1]), argv[1]);
  blurcue::protocol::Procedure p;
  p.kind = blurcue::protocol::Procedure::Kind::kQuestPlus;
  p.stimuli = in["stimuli"].get<std::vector<double>>();
  p.thresholds = in["threshold"].get<std::vector<double>>();
  p.slopes = in["slope"].get<std::vector<double>>();
  p.lapses = in["lapse"].get<std::vector<double>>();
  p.guess = in["guess"].get<double>();
  const double t = in["observer"]["threshold"], b = in["observer"]["slope"], l = in["observer"]["lapse"];
  blurcue::procedure::QuestPlus q(p);
  blurcue::Json shown = blurcue::Json::array();
  for (const auto& u : in["u"]) {
    const double x = q.Next();
    const double pc = 1 - l - (1 - p.guess - l) * std::exp(-std::pow(x / t, b));
    q.Update(x, u.get<double>() < pc);
    shown.push_back(x);
  }
  std::cout << blurcue::Json{{"stimuli", shown},
                             {"posterior", q.Posterior()},
                             {"mean_threshold", q.MeanThreshold()},
                             {"mean_slope", q.MeanSlope()}}
                   .dump()
            << "\n";
  return 0;
}
