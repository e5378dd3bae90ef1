#include "paper/PublishedValues.h"

#include <map>
#include <stdexcept>

namespace misalloc {

namespace {

constexpr const char* kCorrect = "correct";
constexpr const char* kTruncated = "correct (truncated, not rounded)";
constexpr const char* kNotInPaper = "not in the paper";

const char* const k000C = "[HS14] App. C";
const char* const k001Flatland = "[Kar19] Sec. 6.3";
constexpr const char* kMapUnknown = "not reproducible (map unknown); same order of magnitude";
const char* const k002Ex[] = {"", "[SHS16] App. A, Ex. 1", "[SHS16] App. A, Ex. 2", "[SHS16] App. A, Ex. 3", "[SHS16] App. A, Ex. 4"};

// The three tables of [SHS16] App. A hold one row per example.
std::vector<PublishedValue> tables002(const char* v1n, const char* vHeur, const char* eq44_1n, const char* eq44Heur,
                                      const char* t4_1n, const char* t4Heur, const char* t5Sigma, const char* t5Equal,
                                      std::vector<const char*> verdicts) {
  return {{"Table 3: V at alpha = 1/n", v1n, "[SHS16] Table 3", verdicts[0]},
          {"Table 3: V at alpha ~ 1/V[G]", vHeur, "[SHS16] Table 3", verdicts[1]},
          {"Table 3: eq. 44 at alpha = 1/n", eq44_1n, "[SHS16] Table 3", verdicts[2]},
          {"Table 3: eq. 44 at alpha ~ 1/V[G]", eq44Heur, "[SHS16] Table 3", verdicts[3]},
          {"Table 4: cost x V at alpha = 1/n", t4_1n, "[SHS16] Table 4", verdicts[4]},
          {"Table 4: cost x V at alpha ~ 1/(cV)", t4Heur, "[SHS16] Table 4", verdicts[5]},
          {"Table 5: cost x V, n ~ sigma/sqrt(c)", t5Sigma, "[SHS16] Table 5", verdicts[6]},
          {"Table 5: cost x V, equal count", t5Equal, "[SHS16] Table 5", verdicts[7]}};
}

std::vector<PublishedValue> concat(std::vector<PublishedValue> a, const std::vector<PublishedValue>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

const std::map<std::string, std::vector<PublishedValue>>& allPublishedValues() {
  static const std::map<std::string, std::vector<PublishedValue>> table = {
      {"000-C",
       {{"I", "10.2884", k000C, kCorrect},
        {"s1 = int x", "4.9348", k000C, "correct (printed as pi^2/2)"},
        {"s2 = int (x^2 - x/pi)", "8.764", k000C,
         "correct but truncated; the first block of numbers uses the printed 8.764, the cost block the exact value"},
        {"s3 = int sin x", "2", k000C, kCorrect},
        {"V1", "29.7928", k000C, kCorrect},
        {"V2 (s2 = 8.764)", "23.4828", k000C,
         "correct as the eq. 4.18 integral, but x^2 - x/pi < 0 on (0, 1/pi): technique 2 is no density on [0, pi] "
         "and V2 no sampler's variance (002 moves the domain to [3/(2pi), pi])"},
        {"V3", "123.896", k000C, kCorrect},
        {"H(V1, V2, V3)", "35.6206", k000C, "correct (s2 = 8.764)"},
        {"alpha, eq. 4.17", "(0.398538, 0.505627, 0.0958351)", k000C, "correct (s2 = 8.764)"},
        {"V(alpha), eq. 4.5", "25.803", k000C, kCorrect},
        {"V(1/3, 1/3, 1/3)", "33.4113", k000C, kCorrect},
        {"gain equal -> heuristic (%)", "30", k000C, "correct (29.5, rounded)"},
        {"lambda, eq. 4.11, at alpha", "131.654", k000C, kCorrect},
        {"E_j, eq. 4.9, at alpha", "(128.466, 137.427, 114.445)", k000C, kTruncated},
        {"lambda at alpha = 1/3", "139.262", k000C, kCorrect},
        {"E_j at alpha = 1/3", "(143.513, 162.005, 112.267)", k000C, kCorrect},
        {"grid minimum of V (step 0.01)", "23.247", k000C,
         "wrong: a quadrature artifact at a 'mixture' that is negative near 0, where 1/p has a pole inside the "
         "domain; ours is the minimum over valid mixtures"},
        {"alpha with costs, eq. 4.20 (exact s2)", "(0.783361, 0.159209, 0.0574306)", k000C,
         "correct with the exact s2"},
        {"V(alpha with costs)", "28.9247", k000C, kCorrect},
        {"relative efficiency, equal cost", "1.2947", k000C, "correct: V(1/3, 1/3, 1/3) / V(alpha), exact s2"},
        {"relative efficiency, with costs", "2.06141", k000C,
         "correct: [mean(c) V(1/3, 1/3, 1/3)] / [(sum c alpha) V(alpha)], exact s2"},
        {"alpha in Fig. 4.1", "(0.391, 0.520, 0.089)", "[HS14] Fig. 4.1",
         "not reproducible (probably a pilot-sample estimate); eq. 4.17 gives ours"},
        {"Fig. 4.1 caption: efficiency gain (%)", "138", "[HS14] Fig. 4.1",
         "wrong: App. D's gain copied into this caption"},
        {"Sec. 5.1: efficiency gain (%)", "29", "[HS14] Sec. 5.1",
         "consistent: the paper's value comes from one run of 1000 samples with 200 pilot samples"},
        {"minimum of V over valid mixtures", nullptr, k000C,
         "not in the paper: on the positivity edge p'(0) = 0 (s2 = 8.764)"},
        {"cost-aware optimum (exact s2)", nullptr, k000C, "not in the paper: sampling x alone is optimal"}}},
      {"002-1",
       concat({{"int_a^pi x", "4.82082", k002Ex[1], "correct (the text prints the upper limit pi/2; pi is meant)"},
               {"int_a^pi (x^2 - x/pi)", "8.76463", k002Ex[1], kCorrect},
               {"int_a^pi sin x", "1.88816", k002Ex[1], kCorrect},
               {"I", "10.2876", k002Ex[1], kCorrect},
               {"V[G1], V[G2], V[G3]", "(26.6759, 23.507, 111.065)", k002Ex[1], kCorrect},
               {"alpha ~ 1/V[G]", "(0.42105, 0.47782, 0.10113)", k002Ex[1], kCorrect},
               {"V(alpha ~ 1/V[G])", "24.2211", k002Ex[1],
                "correct; eq. 52's printed constants (2/pi^2, 1/8.764, 1/2) are copied from 000 and do not "
                "belong to this domain"},
               {"V(1/3, 1/3, 1/3)", "30.1676", k002Ex[1], kCorrect},
               {"gain (%)", "24.55", k002Ex[1], kCorrect},
               {"relative efficiency, equal cost", "1.24", k002Ex[1], kTruncated},
               {"relative efficiency, with costs", "2.12", k002Ex[1], kTruncated}},
              tables002("30.167", "24.221", "1.004", "0.10946", "105.788", "49.750", "89.40", "102.26",
                        {kTruncated, kCorrect, kCorrect, kCorrect, kCorrect, kTruncated, kTruncated, kTruncated}))},
      {"002-2",
       concat({{"I", "3.59615", k002Ex[2], kCorrect},
               {"V[G1], V[G2], V[G3]", "(5.6334, 9.41988, 4.54464)", k002Ex[2], kCorrect},
               {"alpha ~ 1/V[G]", "(0.35241, 0.21075, 0.43684)", k002Ex[2], kCorrect},
               {"V(alpha ~ 1/V[G])", "4.6041", k002Ex[2],
                "correct (the text writes V(5.6334, 9.41988, 4.54464), the V[G] for alpha: a typo)"},
               {"V(1/3, 1/3, 1/3)", "5.01917", k002Ex[2], kCorrect},
               {"gain (%)", "9", k002Ex[2], kCorrect},
               {"relative efficiency, with costs", "1.87", k002Ex[2], kTruncated}},
              tables002("5.01917", "4.6041", "0.102", "0.05131", "19.470", "10.466", "15.441", "17.244",
                        {kCorrect, kCorrect, kCorrect, kCorrect,
                         "not reproducible: the setup that reproduces every other number gives ours, which the "
                         "text's quotient 1.87 also implies; eq. 52's printed constants come closest",
                         "not reproducible, as the previous row", "minor discrepancy", kCorrect}))},
      {"002-3",
       concat({{"I", "15.4736", k002Ex[3], kCorrect},
               {"V[G1], V[G2]", "(4.09963, 35.3278)", k002Ex[3], kCorrect},
               {"V[G3]", "9586.73", k002Ex[3],
                "wrong: int f^2/sin x diverges at pi (f(pi) = pi^2 + pi - 1 != 0); the number is a quadrature "
                "artifact"},
               {"alpha ~ 1/V[G]", "(0.89568, 0.10394, 0.00038)", k002Ex[3],
                "follows from the artifact V[G3]; with V[G3] infinite alpha3 = 0"},
               {"V(alpha ~ 1/V[G])", "2.04964", k002Ex[3], "follows from the artifact V[G3]"},
               {"V(1/3, 1/3, 1/3)", "13.354", k002Ex[3], kCorrect},
               {"gain (%)", "551.21", k002Ex[3],
                "follows from the artifact V[G3], and not even exactly; with alpha3 = 0 the gain is larger"},
               {"relative efficiency, with costs", "11.57", k002Ex[3], "follows from the artifact V[G3]"}},
              tables002("13.354", "2.050", "2.666", "0.02897", "46.827", "4.047", "31.08", "37.478",
                        {kCorrect, "follows from the artifact V[G3]", kCorrect, "follows from the artifact V[G3]",
                         kTruncated, "follows from the artifact V[G3]", "typo: two digits transposed", kCorrect}))},
      {"002-4",
       concat({{"I", "3", k002Ex[4],
                "correct: eq. 55 divides by the rounded 8.764, the density by the exact integral, hence not exactly 3"},
               {"V[G3]", nullptr, k002Ex[4], "the paper gives none; it diverges at pi as in Example 3"},
               {"V(1/3, 1/3, 1/3)", "0", k002Ex[4], "correct up to the rounding of 8.764"},
               {"V(alpha ~ 1/V[G])", "0.121359", k002Ex[4],
                "not reproducible: it depends on a finite value for the divergent V[G3]"}},
              tables002("0", "0.121", "0", "0.00039", "0", "0.110", "0", "0",
                        {kCorrect, "follows from a finite V[G3]", kCorrect, "follows from a finite V[G3]", kCorrect,
                         "correct (alpha3 = 0)", "correct up to the rounding of 8.764",
                         "correct up to the rounding of 8.764"}))},
      // [Kar19]'s map is not in the text: our numbers are for map A, verified_values.json's stand-in.
      {"001-6.3",
       {{"diffuse, one-sample: NMSE(HDR only) / NMSE(MIS)", "roughly equal", k001Flatland,
         "qualitatively reproduced (map A)"},
        {"diffuse, one-sample gain over MIS: practical-ni", "3.7", k001Flatland, kMapUnknown},
        {"diffuse, one-sample gain over MIS: practical-nd", "7.5", k001Flatland, kMapUnknown},
        {"diffuse, one-sample gain over MIS: MIS-compensated", "7.5", k001Flatland,
         "not reproducible (map unknown); equal to practical-nd for a diffuse BRDF, as the paper states"},
        {"diffuse, one-sample gain over MIS: optimal", "7.5", k001Flatland, kMapUnknown},
        {"sharp, one-sample gain over MIS: practical-ni, practical-nd", "no improvement, not worse", k001Flatland,
         "map dependent: a mild improvement with map A, 0.78x with a strong sun outside the lobe"},
        {"sharp, one-sample: MIS-compensated vs BRDF only", "847", k001Flatland, kMapUnknown},
        {"sharp, one-sample: MIS-compensated vs MIS", "4809", k001Flatland, kMapUnknown},
        {"int (p_comp - p_opt)^2 / int p_opt^2 (diffuse, sharp)", "< 1e-5", k001Flatland,
         "map dependent (the paper's metric is not specified)"},
        {"lambda in [c F^2, F^2/c], eq. 10 (diffuse, sharp)", "holds", "[Kar19] eq. 10", kCorrect}}},
      {"003-1",
       {{"integral", "25.3065", "[SS23] eq. 20", "correct; printed under Example 2"},
        {"V, equal budget", "24.1152", "[SS23] Ex. 1", kCorrect},
        {"V minimum", nullptr, "[SS23] Fig. 4", kNotInPaper},
        {"alpha at minimum", nullptr, "[SS23] Fig. 4", kNotInPaper}}},
      {"003-2",
       {{"integral", "2.9929", "[SS23] eq. 21", "correct; printed under Example 3"},
        {"V, equal budget", "0.1134", "[SS23] Ex. 2", kCorrect},
        {"V minimum", nullptr, "[SS23] Fig. 7", "not in the paper: f is a mixture of the two pdfs, zero variance"},
        {"alpha at minimum", nullptr, "[SS23] Fig. 7", kNotInPaper}}},
      {"003-3",
       {{"integral", "2.3118", "[SS23] eq. 22", "correct; printed under Example 4"},
        {"V, equal budget", "0.2772", "[SS23] Ex. 3", kCorrect},
        {"V minimum", nullptr, "[SS23] Fig. 10", kNotInPaper},
        {"alpha at minimum", nullptr, "[SS23] Fig. 10", kNotInPaper}}},
      {"003-4",
       {{"integral", "5.8394", "[SS23] eq. 23", "correct; printed under Example 5"},
        {"V, equal budget", "6.8063", "[SS23] Ex. 4", kCorrect},
        {"V minimum", "3.0454", "[SS23] Ex. 4", kCorrect},
        {"alpha at minimum", nullptr, "[SS23] Ex. 4", kNotInPaper}}},
      {"003-5",
       {{"integral", "12.7484", "[SS23] eq. 24", kCorrect},
        {"V, equal budget", "14.4033", "[SS23] Ex. 5", kCorrect},
        {"V minimum", "1.7217", "[SS23] Ex. 5", kCorrect},
        {"alpha at minimum", nullptr, "[SS23] Ex. 5", kNotInPaper}}},
      {"003-6",
       {{"integral", "3.5962", "[SS23] eq. 25", "correct up to double rounding (002 prints 3.59615)"},
        {"V, equal budget", "4.9175", "[SS23] Ex. 6", kTruncated},
        {"V minimum", "4.1945", "[SS23] Ex. 6", kCorrect},
        {"alpha at minimum", "(0, 0.1986, 0.8014)", "[SS23] Ex. 6", "correct: the optimum is on the boundary"}}},
  };
  return table;
}

}  // namespace

const std::vector<PublishedValue>& publishedValues(const std::string& exampleId) {
  const auto& table = allPublishedValues();
  auto it = table.find(exampleId);
  if (it == table.end()) throw std::invalid_argument("no published values for example '" + exampleId + "'");
  return it->second;
}

std::optional<LinearHeuristicReference> linearHeuristicReference(const std::string& exampleId) {
  static const std::map<std::string, LinearHeuristicReference> reference = {
      {"003-1", {{13.53795403, 13.50684024, 13.57535943}, {13.53795403, 13.50684024, 13.57535943}}},
      {"003-2",
       {{1.421085472e-14, 1.065814104e-14, 1.776356839e-14}, {1.421085472e-14, 1.065814104e-14, 1.776356839e-14}}},
      {"003-3", {{0.09070271438, 0.09034089782, 0.09270062941}, {0.09070271438, 0.09034089782, 0.09270062941}}},
      {"003-4", {{3.16127859, 3.087225863, 3.352797285}, {3.16127859, 3.087225863, 3.352797285}}},
      {"003-5", {{2.630500318, 1.972837793, 3.061008605}, {2.319140931, 1.972837793, 2.844626973}}},
      {"003-6", {{4.218653505, 4.196810833, 4.330166968}, {4.213180849, 4.195646606, 4.300852023}}},
  };
  auto it = reference.find(exampleId);
  if (it == reference.end()) return std::nullopt;
  return it->second;
}

}  // namespace misalloc
