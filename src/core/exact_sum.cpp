#include "mupm/core/exact_sum.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace mupm {

std::vector<double> exact_sums(MPI_Comm comm, const double* terms, std::size_t rows, int width) {
  const std::size_t w = static_cast<std::size_t>(width);
  // The largest |term| of each column over all ranks (infinity where a term is not finite).
  std::vector<double> big(w, 0.0);
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < w; ++c) {
      const double t = terms[r * w + c];
      big[c] = std::isfinite(t) ? std::fmax(big[c], std::fabs(t)) : HUGE_VAL;
    }
  MPI_Allreduce(MPI_IN_PLACE, big.data(), width, MPI_DOUBLE, MPI_MAX, comm);
  long long total = static_cast<long long>(rows);
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_LONG_LONG, MPI_SUM, comm);
  if (total > (1LL << 30))
    throw std::length_error("exact_sums: " + std::to_string(total) +
                            " rows over the ranks; at most 2^30 sum exactly");
  // e of each column: its largest |term| < 2^e (frexp: big = f 2^e, 0.5 <= f < 1).
  std::vector<int> e(w, 0);
  for (std::size_t c = 0; c < w; ++c)
    if (big[c] > 0 && big[c] < HUGE_VAL)
      std::frexp(big[c], &e[c]);
  std::vector<std::int64_t> sums(2 * w, 0);  // hi, lo of each column
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < w; ++c) {
      const double t = terms[r * w + c];
      if (t == 0 || big[c] == HUGE_VAL)
        continue;
      const double q = std::ldexp(t, 32 - e[c]);  // exact: a power of two
      const double hi = std::trunc(q);
      const double frac = q - hi;  // exact (the bits of q below its units), in (-1, 1)
      sums[2 * c] += static_cast<std::int64_t>(hi);
      sums[2 * c + 1] += static_cast<std::int64_t>(std::nearbyint(std::ldexp(frac, 32)));
    }
  MPI_Allreduce(MPI_IN_PLACE, sums.data(), 2 * width, MPI_INT64_T, MPI_SUM, comm);
  std::vector<double> out(w, 0.0);
  for (std::size_t c = 0; c < w; ++c)
    out[c] =
        big[c] == HUGE_VAL
            ? NAN
            : std::ldexp(double(sums[2 * c]) + std::ldexp(double(sums[2 * c + 1]), -32), e[c] - 32);
  return out;
}

}  // namespace mupm
