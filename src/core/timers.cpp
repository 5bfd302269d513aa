#include "mupm/core/timers.hpp"

#include <Kokkos_Core.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <unordered_map>

namespace mupm::timers {

namespace {

using Clock = std::chrono::steady_clock;

struct State {
  std::unordered_map<std::string, std::size_t> index;
  std::vector<Entry> entries;
  std::vector<std::pair<std::size_t, Clock::time_point>> kernels, regions;  // open ones
  bool enabled = false;
  bool in_loop = false;                                        // time_loop(true) .. (false)
  std::map<std::string, std::pair<long long, double>> allocs;  // in the loop: count, bytes
  std::mutex allocs_lock;
};
State& state() {
  static State s;
  return s;
}

std::size_t slot(const char* name, bool region) {
  State& s = state();
  // Kokkos labels each View's fill "Kokkos::View::initialization [label]": one row for all.
  static const std::string init = "Kokkos::View::initialization";
  if (std::strncmp(name, init.c_str(), init.size()) == 0)
    name = "Kokkos::View::initialization";
  std::string key = (region ? "R:" : "K:") + std::string(name);
  auto it = s.index.find(key);
  if (it != s.index.end())
    return it->second;
  s.entries.push_back(Entry{name, region, 0.0, 0});
  s.index.emplace(std::move(key), s.entries.size() - 1);
  return s.entries.size() - 1;
}

void begin_kernel(const char* name, const std::uint32_t, std::uint64_t* id) {
  State& s = state();
  *id = s.kernels.size();
  s.kernels.emplace_back(slot(name, false), Clock::now());
}
void end_kernel(std::uint64_t) {
  State& s = state();
  if (s.kernels.empty())
    return;
  const auto [k, t0] = s.kernels.back();
  s.kernels.pop_back();
  s.entries[k].seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  ++s.entries[k].calls;
}
void push_region(const char* name) {
  State& s = state();
  s.regions.emplace_back(slot(name, true), Clock::now());
}
void pop_region() {
  State& s = state();
  if (s.regions.empty())
    return;
  const auto [k, t0] = s.regions.back();
  s.regions.pop_back();
  s.entries[k].seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  ++s.entries[k].calls;
}

// Kokkos calls this from every thread of the pool at once when an OpenMP reduction or team
// needs more scratch (OpenMPExec::resize_thread_data allocates each thread's block in its own
// thread), so the tally is locked. The kernel and region callbacks come from the master only.
void allocate(Kokkos::Tools::SpaceHandle, const char* label, const void*, std::uint64_t bytes) {
  State& s = state();
  if (!s.in_loop)
    return;
  const std::lock_guard<std::mutex> hold(s.allocs_lock);
  auto& a = s.allocs[label && *label ? label : "(unlabelled)"];
  ++a.first;
  a.second += double(bytes);
}

}  // namespace

void time_loop(bool inside) {
  state().in_loop = inside;
}

long long loop_allocations() {
  const std::lock_guard<std::mutex> hold(state().allocs_lock);
  long long n = 0;
  for (const auto& a : state().allocs)
    n += a.second.first;
  return n;
}

bool enable() {
  if (std::getenv("KOKKOS_TOOLS_LIBS") || std::getenv("KOKKOS_PROFILE_LIBRARY"))
    return false;
  namespace KT = Kokkos::Tools::Experimental;
  KT::set_begin_parallel_for_callback(begin_kernel);
  KT::set_end_parallel_for_callback(end_kernel);
  KT::set_begin_parallel_reduce_callback(begin_kernel);
  KT::set_end_parallel_reduce_callback(end_kernel);
  KT::set_begin_parallel_scan_callback(begin_kernel);
  KT::set_end_parallel_scan_callback(end_kernel);
  KT::set_push_region_callback(push_region);
  KT::set_pop_region_callback(pop_region);
  KT::set_allocate_data_callback(allocate);
  state().enabled = true;
  return true;
}

void disable() {
  if (!state().enabled)
    return;
  namespace KT = Kokkos::Tools::Experimental;
  KT::set_begin_parallel_for_callback(nullptr);
  KT::set_end_parallel_for_callback(nullptr);
  KT::set_begin_parallel_reduce_callback(nullptr);
  KT::set_end_parallel_reduce_callback(nullptr);
  KT::set_begin_parallel_scan_callback(nullptr);
  KT::set_end_parallel_scan_callback(nullptr);
  KT::set_push_region_callback(nullptr);
  KT::set_pop_region_callback(nullptr);
  KT::set_allocate_data_callback(nullptr);
  state().enabled = false;
}

void reset() {
  State& s = state();
  for (auto& e : s.entries) {
    e.seconds = 0;
    e.calls = 0;
  }
  s.allocs.clear();
}

std::vector<Entry> local_entries() {
  return state().entries;
}

void report(MPI_Comm comm, std::ostream& out) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // Rank 0's labels decide the rows; every rank reports its time for each of them.
  std::string labels;
  const auto mine = local_entries();
  if (rank == 0)
    for (const auto& e : mine)
      labels += (e.region ? 'R' : 'K') + e.label + '\n';
  int len = static_cast<int>(labels.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, comm);
  labels.resize(static_cast<std::size_t>(len));
  if (len > 0)
    MPI_Bcast(&labels[0], len, MPI_CHAR, 0, comm);
  std::vector<std::string> rows;
  for (std::size_t p = 0, q; p < labels.size(); p = q + 1) {
    q = labels.find('\n', p);
    rows.push_back(labels.substr(p, q - p));
  }
  std::vector<double> t(rows.size(), 0.0), tmin(rows.size()), tmax(rows.size());
  std::vector<long long> calls(rows.size(), 0);
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (const auto& e : mine)
      if ((e.region ? 'R' : 'K') + e.label == rows[r]) {
        t[r] = e.seconds;
        calls[r] = e.calls;
      }
  const int n = static_cast<int>(rows.size());
  MPI_Reduce(t.data(), tmin.data(), n, MPI_DOUBLE, MPI_MIN, 0, comm);
  MPI_Reduce(t.data(), tmax.data(), n, MPI_DOUBLE, MPI_MAX, 0, comm);
  long long allocs = loop_allocations(), max_allocs = 0;
  MPI_Reduce(&allocs, &max_allocs, 1, MPI_LONG_LONG, MPI_MAX, 0, comm);
  if (rank != 0)
    return;
  std::vector<std::size_t> order(rows.size());
  for (std::size_t r = 0; r < order.size(); ++r)
    order[r] = r;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (rows[a][0] != rows[b][0])
      return rows[a][0] > rows[b][0];  // regions first
    return tmax[a] > tmax[b];
  });
  char line[256];
  std::snprintf(line, sizeof line, "%-6s %-52s %10s %12s %12s\n", "kind", "label", "calls", "min s",
                "max s");
  out << "Kernel and region times over " << size << " rank(s):\n" << line;
  for (std::size_t r : order) {
    std::snprintf(line, sizeof line, "%-6s %-52s %10lld %12.4f %12.4f\n",
                  rows[r][0] == 'R' ? "region" : "kernel", rows[r].c_str() + 1, calls[r], tmin[r],
                  tmax[r]);
    out << line;
  }
  // Views allocated between time_loop(true) and time_loop(false): a time loop should allocate
  // none (each allocation is a system call and a fill, and a device backend would serialize).
  out << "View allocations in the time loop: " << max_allocs << " (most on a rank)";
  if (!state().allocs.empty()) {
    out << "; rank 0's by label (count, MiB):";
    for (const auto& a : state().allocs)
      out << "\n  " << a.first << " " << a.second.first << " " << a.second.second / 1048576.0;
  }
  out << "\n";
}

}  // namespace mupm::timers
