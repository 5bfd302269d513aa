// What one core of this machine can do, to place the kernels against (perf/README.md, "The
// limit"): the floating-point throughput of the instructions mupm's kernels compile to, of the
// vector FMAs the core has, and the memory bandwidth of a stream.
//
// - BM_ScalarMulAdd: a*x + y on scalars in 12 independent chains, one scalar mul and add each
//   (vectorization off): what a kernel whose bond loop the compiler does not vectorize can reach
//   in the generic x86-64 build (MUPM_NATIVE=OFF: SSE2, no FMA instruction). 2 flops an element.
// - BM_Sse2MulAdd: the same, vectorized by the compiler to SSE2 (2 doubles a register).
//   Both are compiled without AVX (target "no-avx", which also removes AVX2, FMA and AVX-512),
//   so that they measure the same instructions in the default -march=native build.
// - BM_VectorFma: the same on arrays the compiler vectorizes, with the core's widest FMA
//   (target attribute: AVX-512F where the core has it, else AVX2 + FMA; both chosen at run time).
// - BM_StreamTriad: a = b + s c over arrays of 3 x 64 MiB, OpenMP threads (24 bytes an element
//   moved by the program, 32 with the write-allocate of a).
// Wall clock; flops_per_s and bytes_per_s are the counters to read.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <cstddef>
#include <memory>

namespace {

// Independent accumulators: enough to cover the add latency, few enough that they and the two
// constants stay in the 16 SSE registers (with 16, GCC kept 3 chains in general registers).
constexpr int kChains = 12;
constexpr long kRounds = 1 << 20;

__attribute__((noinline, optimize("no-tree-vectorize"), target("no-avx"))) void scalar_rounds(
    double* acc, long rounds) {
  const double a = 0.999999, x = 1e-9;
  for (long r = 0; r < rounds; ++r)
    for (int c = 0; c < kChains; ++c)
      acc[c] = a * acc[c] + x;
}
__attribute__((noinline, target("no-avx"))) void sse2_rounds(double* acc, long rounds) {
  const double a = 0.999999, x = 1e-9;
  for (long r = 0; r < rounds; ++r)
    for (int c = 0; c < kChains; ++c)
      acc[c] = a * acc[c] + x;
}

template <void (*Rounds)(double*, long)>
void BM_MulAdd(benchmark::State& state) {
  alignas(64) double acc[kChains];
  for (int c = 0; c < kChains; ++c)
    acc[c] = 1.0 + 1e-3 * c;
  for (auto _ : state) {
    Rounds(acc, kRounds);
    benchmark::DoNotOptimize(acc);
  }
  state.counters["flops_per_s"] = benchmark::Counter(2.0 * kChains * double(kRounds),
                                                     benchmark::Counter::kIsIterationInvariantRate);
}
void BM_ScalarMulAdd(benchmark::State& state) {
  BM_MulAdd<scalar_rounds>(state);
}
void BM_Sse2MulAdd(benchmark::State& state) {
  BM_MulAdd<sse2_rounds>(state);
}

#if defined(__x86_64__)
// 8 chains of 8 doubles: 64 accumulators, one AVX-512 register each or two AVX2 registers.
// std::fma, not a * acc + x: the build does not contract (-ffp-contract=off, MUPM_NATIVE), and
// a multiply and an add would measure half the FMA rate. The AVX-512 loop asks for 512-bit
// vectors: -march=native's tuning for these cores prefers 256 (prefer-vector-width).
#define MUPM_VECTOR_ROUNDS             \
  const double a = 0.999999, x = 1e-9; \
  for (long r = 0; r < rounds; ++r)    \
    _Pragma("GCC ivdep") for (int c = 0; c < 64; ++c) acc[c] = std::fma(a, acc[c], x);
__attribute__((noinline, target("avx512f,fma,prefer-vector-width=512"))) void rounds_avx512(
    double* acc, long rounds) {
  MUPM_VECTOR_ROUNDS
}
__attribute__((noinline, target("avx2,fma"))) void rounds_avx2(double* acc, long rounds) {
  MUPM_VECTOR_ROUNDS
}
#undef MUPM_VECTOR_ROUNDS

void BM_VectorFma(benchmark::State& state) {
  alignas(64) double acc[64];
  for (int c = 0; c < 64; ++c)
    acc[c] = 1.0 + 1e-3 * c;
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f");
  if (!avx512 && !(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))) {
    state.SkipWithError("no AVX2 with FMA on this core");
    return;
  }
  for (auto _ : state) {
    if (avx512)
      rounds_avx512(acc, kRounds);
    else
      rounds_avx2(acc, kRounds);
    benchmark::DoNotOptimize(acc);
  }
  state.SetLabel(avx512 ? "AVX-512 FMA" : "AVX2 FMA");
  state.counters["flops_per_s"] =
      benchmark::Counter(2.0 * 64 * double(kRounds), benchmark::Counter::kIsIterationInvariantRate);
}
#endif

void BM_StreamTriad(benchmark::State& state) {
  const std::size_t n = std::size_t(64) << 17;  // 8 M doubles = 64 MiB an array
  const int threads = int(state.range(0));
  // Not value-initialized (std::vector would touch every page on this thread): the pages are
  // first touched by the threads that use them.
  std::unique_ptr<double[]> a(new double[n]), b(new double[n]), c(new double[n]);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = 0;
    b[i] = 1;
    c[i] = 2;
  }
  const double s = 0.5;
  for (auto _ : state) {
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::size_t i = 0; i < n; ++i)
      a[i] = b[i] + s * c[i];
    benchmark::DoNotOptimize(a.get());
    benchmark::ClobberMemory();
  }
  state.counters["bytes_per_s"] =
      benchmark::Counter(24.0 * double(n), benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

BENCHMARK(BM_ScalarMulAdd)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Sse2MulAdd)->UseRealTime()->Unit(benchmark::kMillisecond);
#if defined(__x86_64__)
BENCHMARK(BM_VectorFma)->UseRealTime()->Unit(benchmark::kMillisecond);
#endif
BENCHMARK(BM_StreamTriad)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
