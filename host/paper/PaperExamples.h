#pragma once
// The 1D examples of papers 000 (App. C), 002 (App. A) and 003 (Sec. 6.1).

#include <string>
#include <vector>

#include "paper/Example1D.h"

namespace misalloc {

// [HS14] App. C prints ∫_0^π (x² − x/π) dx = 8.764 (truncated from 8.764629) and uses that
// value in its first block of numbers; its cost block uses the exact one.
enum class AppendixCNormalisation { AsPrinted, Exact };

// [HS14] App. C: f = x (x² − x/π) sin x on [0, π], techniques ∝ x, x² − x/π, sin x with
// costs 1, 6.24, 3.28. x² − x/π is negative on (0, 1/π): technique 2 is not a density.
Example1D example000AppendixC(AppendixCNormalisation normalisation);

// [SHS16] App. A, Examples 1–4: the same techniques on [3/(2π), π], where all three are
// densities, with f = x (x² − x/π) sin x, (x² − x/π) sin² x, x + (x² − x/π) + sin x, and
// the sum of the three densities written with the printed constants.
Example1D example002(int number);

// [SS23] Sec. 6.1, Examples 1–6, with the integrand of each example as mapped in
// verified_values.json (the extracted text prints every integral one example late).
// Gaussian pdfs are truncated to the domain and renormalised.
Example1D example003(int number);

// "000-C", "002-1" … "002-4", "003-1" … "003-6".
std::vector<std::string> paperExampleIds();

// The example with that id (000-C with the exact normalisation). Throws
// std::invalid_argument listing the valid ids otherwise.
Example1D paperExample(const std::string& id);

}  // namespace misalloc
