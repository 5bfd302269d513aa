// Sums over ranks whose bits do not depend on how the terms are ordered or split over ranks and
// threads, with messages of a fixed size: each term is cut, on a grid set by the largest term of
// its column over all ranks, into two integers that add exactly (integer addition is
// associative), and only the integer sums travel (MPI_Allreduce).
//
// Column c with largest |term| < 2^e: q = t 2^(32-e) (|q| < 2^32), hi = trunc(q) (|hi| < 2^32),
// lo = the nearest integer to (q - hi) 2^32 (q - hi is exact, in (-1, 1), so |lo| <= 2^32); the
// sum is (sum hi + 2^-32 sum lo) 2^(e-32). A term loses at most 2^(e-65) (half a unit of lo):
// relative to the largest term 2^-64, 1e-19, far below a double's round-off of the sum. Up to
// 2^30 terms a column over all ranks (the integer sums then stay within 2^62); more throws. A
// column with a term that is not finite sums to NaN.
#ifndef MUPM_CORE_EXACT_SUM_HPP
#define MUPM_CORE_EXACT_SUM_HPP

#include <mpi.h>

#include <cstddef>
#include <vector>

namespace mupm {

// Column sums over all ranks of this rank's `rows` rows of `width` terms (row-major in
// `terms`). Collective; every rank gets the same `width` sums, the same bits on any number of
// ranks.
std::vector<double> exact_sums(MPI_Comm comm, const double* terms, std::size_t rows, int width);

}  // namespace mupm

#endif
