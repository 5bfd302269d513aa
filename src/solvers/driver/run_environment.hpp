// The run's surroundings: wall-clock formatting, the output folder and its lock, the threads'
// placement. A part of the driver (src/solvers/simulation.cpp), which alone includes it.
#ifndef MUPM_DRIVER_RUN_ENVIRONMENT_HPP
#define MUPM_DRIVER_RUN_ENVIRONMENT_HPP

#include <fcntl.h>
#include <mpi.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>
#include <Teuchos_Comm.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "mupm/core/error.hpp"
#include "mupm/core/types.hpp"
#include "mupm/input/input.hpp"
#include "mupm/io/hdf5_io.hpp"

namespace mupm::driver {

using Clock = std::chrono::steady_clock;

inline std::string format_seconds(double s) {
  char buf[64];
  if (s < 120)
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  else if (s < 7200)
    std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else
    std::snprintf(buf, sizeof buf, "%.2f h", s / 3600);
  return buf;
}

inline double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

inline std::string shortest(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The output folder's lock, held by rank 0 for the whole run: two runs writing one folder would
// interleave their time series and leave one's input beside the other's checkpoint. An advisory
// flock() on Output->Folder/run.lock, which the kernel releases when the process ends however it
// ends (a crash or SIGKILL leaves no stale lock; the file itself stays). The file holds the
// holder's process id and host for the message of a run refused.
class FolderLock {
 public:
  FolderLock() = default;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock() {
    if (fd_ >= 0)
      close(fd_);  // releases the lock
  }
  // "" when taken, else why not.
  std::string take(const std::string& folder) {
    const std::string path = folder + "/run.lock";
    fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      return "cannot open " + path + ": " + std::strerror(errno);
    if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      char holder[256] = {};
      const ssize_t n = pread(fd_, holder, sizeof holder - 1, 0);
      std::string who = n > 0 ? std::string(holder, std::size_t(n)) : "";
      while (!who.empty() && (who.back() == '\n' || who.back() == ' '))
        who.pop_back();
      close(fd_);
      fd_ = -1;
      if (err != EWOULDBLOCK) {
        // A file system without locks (Lustre mounted without -o flock): run unguarded.
        unguarded_ = "mupm: WARNING: cannot lock " + path + " (" + std::strerror(err) +
                     "): nothing stops a second run from writing into this folder meanwhile.\n";
        return "";
      }
      return "another mupm run is writing it (" + (who.empty() ? "holder unknown" : who) +
             "; lock file " + path +
             "): two runs in one folder would mix their time series, fields and checkpoints. "
             "Wait for that run to end, or give this one another Output->Folder";
    }
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    const std::string me = "process " + std::to_string(getpid()) + " on host " + host + "\n";
    if (ftruncate(fd_, 0) != 0 || pwrite(fd_, me.data(), me.size(), 0) < 0) {
      // The lock holds without the note; only the message of a refused run loses the holder.
    }
    return "";
  }
  // Why the folder is not locked although take() succeeded ("" when it is).
  const std::string& unguarded() const { return unguarded_; }

 private:
  int fd_ = -1;
  std::string unguarded_;
};

// Creates the output folder, locks it (FolderLock, on rank 0) and writes the resolved input
// there, before the heavy work, so a bad or busy folder fails early.
inline void prepare_folder(const Teuchos::Comm<int>& comm, const std::string& folder,
                           const Teuchos::ParameterList& input, FolderLock& lock,
                           std::ostream& out) {
  int ok = 1;  // 0: cannot write, -1: in use
  std::string why;
  if (comm.getRank() == 0) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) {
      ok = 0;
      why = "cannot write to it: " + ec.message();
    } else if (const std::string busy = lock.take(folder); !busy.empty()) {
      ok = -1;
      why = busy;
    } else {
      out << lock.unguarded();
      // A checkpoint being written when an earlier run was killed.
      std::filesystem::remove(folder + "/checkpoint.h5.tmp", ec);
      try {
        Teuchos::writeParameterListToXmlFile(input, folder + "/input_resolved.xml");
      } catch (const std::exception& e) {
        ok = 0;
        why = std::string("cannot write to it: ") + e.what();
      }
    }
  }
  Teuchos::broadcast(comm, 0, &ok);
  if (ok == 1)
    return;
  long long n = static_cast<long long>(why.size());
  Teuchos::broadcast(comm, 0, &n);
  why.resize(static_cast<std::size_t>(n));
  if (n > 0)
    Teuchos::broadcast(comm, 0, static_cast<int>(n), &why[0]);
  const std::string msg = "Error, mupm->Output->Folder = '" + folder + "': " + why + ".";
  if (ok < 0)
    throw InputError(msg);  // the folder is in use: exit 2, like a folder that is a file
  throw CollectiveError(msg);
}

// Warns (rank 0) when the ranks of a node and their threads do not sit on cores of their own:
// threads x ranks beyond the node's cores, or OpenMP threads pinned (OMP_PROC_BIND not false)
// while the ranks' affinity masks overlap, which puts the threads of every rank on the same
// first cores (measured: the quick start 4-5x slower on 2 ranks).
inline void warn_placement(MPI_Comm comm, int threads, std::ostream& out) {
  MPI_Comm node;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int node_rank = 0, node_size = 1;
  MPI_Comm_rank(node, &node_rank);
  MPI_Comm_size(node, &node_size);
  cpu_set_t mask;
  CPU_ZERO(&mask);
  sched_getaffinity(0, sizeof mask, &mask);
  std::vector<cpu_set_t> masks(static_cast<std::size_t>(node_size));
  MPI_Allgather(&mask, int(sizeof mask), MPI_BYTE, masks.data(), int(sizeof mask), MPI_BYTE, node);
  MPI_Comm_free(&node);
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  const char* bind = std::getenv("OMP_PROC_BIND");
  std::string b = bind ? bind : "";
  for (auto& c : b)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  const bool pinned = !b.empty() && b != "false";
  int shared = 0;
  for (int i = 0; i < node_size && !shared; ++i)
    for (int j = i + 1; j < node_size && !shared; ++j) {
      cpu_set_t both;
      CPU_AND(&both, &masks[std::size_t(i)], &masks[std::size_t(j)]);
      shared = CPU_COUNT(&both) > 0;
    }
  int flags[2] = {long(node_size) * threads > cores ? 1 : 0, pinned && shared ? 1 : 0};
  MPI_Allreduce(MPI_IN_PLACE, flags, 2, MPI_INT, MPI_MAX, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0)
    return;
  const std::string line =
      "OMP_NUM_THREADS=T OMP_PROC_BIND=spread OMP_PLACES=cores mpirun --map-by ppr:R:node:PE=T "
      "--bind-to core -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES mupm input.xml (R ranks "
      "x T threads a node)";
  if (flags[0])
    out << "mupm: WARNING: " << node_size << " rank(s) x " << threads << " thread(s) on a node of "
        << cores
        << " cores: they take turns on the cores and every step waits for the slowest. Launch "
        << line << ".\n";
  if (flags[1])
    out << "mupm: WARNING: ranks on one node share cores while OMP_PROC_BIND = " << bind
        << " pins their threads: the threads of every rank sit on the same first cores. Launch "
        << line << ", or set OMP_PROC_BIND=false.\n";
}

}  // namespace mupm::driver

#endif
