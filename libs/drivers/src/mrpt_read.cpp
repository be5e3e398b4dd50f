#include "mrpt_read.hpp"

#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <new>
#include <stdexcept>

#include "mbot/common/files.hpp"
#include "mbot/common/process.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define MBOT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MBOT_ASAN 1
#endif
#endif
#ifdef MBOT_ASAN
#include <sanitizer/common_interface_defs.h>
#endif

namespace mbot::drivers {

namespace {

// Child side: a crash or an allocation failure ends the child quietly (the parent reports it), and
// the address space is bounded to what it maps now plus `budget`. Under AddressSanitizer (and a
// fuzzer) the sanitizer's and the fuzzer's crash handlers are taken off first: the child's death is
// the expected outcome of a bad file, not a finding.
void BoundAddressSpace(uint64_t budget) {
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
#ifdef MBOT_ASAN
  __sanitizer_set_death_callback(nullptr);
#endif
  const uint64_t now = AddressSpaceBytes();
  rlimit lim{};
  if (now == 0 || getrlimit(RLIMIT_AS, &lim) != 0) return;
  const uint64_t want = now + budget;
  if (lim.rlim_cur != RLIM_INFINITY && lim.rlim_cur <= want) return;
  lim.rlim_cur = want;
  setrlimit(RLIMIT_AS, &lim);
}

std::string MemoryReason(uint64_t budget) {
  return "it asks for more memory than the " + std::to_string(budget >> 20) +
         " MB its size allows (a corrupt count or size field)";
}

// The child's report, in a page shared with the parent.
struct Shared {
  uint64_t records;
  int kind;  // 0 finished, 1 out of memory, 2 exception
  char reason[480];
};

}  // namespace

uint64_t MrptReadBudget(uint64_t file_bytes) {
  constexpr uint64_t kFloor = 256ull << 20;
  return std::max(kFloor, 64 * file_bytes);
}

std::string MrptReason(const std::string& what) {
  const size_t m = what.rfind("Message:");
  const size_t b = m == std::string::npos ? 0 : what.find_first_not_of(' ', m + 8);
  const std::string line = what.substr(b == std::string::npos ? 0 : b);
  return line.substr(0, line.find('\n'));
}

MrptTrial TrialReadMrpt(const std::string& path, const std::function<void(uint64_t* records)>& read) {
  std::error_code ec;
  const uint64_t budget = MrptReadBudget(std::filesystem::file_size(path, ec));
  void* page = mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (page == MAP_FAILED) throw std::runtime_error(path + ": cannot map a page for the trial read");
  auto* shared = new (page) Shared{};
  const pid_t pid = fork();
  if (pid < 0) {
    munmap(page, sizeof(Shared));
    throw std::runtime_error(path + ": cannot fork the trial read: " + std::strerror(errno));
  }
  if (pid == 0) {
    BoundAddressSpace(budget);
    try {
      read(&shared->records);
      shared->kind = 0;
    } catch (const std::bad_alloc&) {
      shared->kind = 1;
    } catch (const std::length_error&) {
      shared->kind = 1;
    } catch (const std::exception& e) {
      const std::string why = MrptReason(e.what());
      shared->kind = why.find("bad_alloc") != std::string::npos ? 1 : 2;
      std::strncpy(shared->reason, why.c_str(), sizeof(shared->reason) - 1);
    } catch (...) {
      shared->kind = 2;
      std::strncpy(shared->reason, "an unknown exception", sizeof(shared->reason) - 1);
    }
    _exit(0);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  MrptTrial out;
  out.records = shared->records;
  if (WIFSIGNALED(status)) {
    out.ok = false;
    const int sig = WTERMSIG(status);
    out.reason = sig == SIGKILL ? MemoryReason(budget)
                                : std::string("MRPT's reader crashed on it (") + strsignal(sig) + "; a corrupt record)";
  } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    out.ok = false;
    out.reason = "the trial read failed (exit " + std::to_string(WEXITSTATUS(status)) + ")";
  } else if (shared->kind == 1) {
    out.ok = false;
    out.reason = MemoryReason(budget);
  } else if (shared->kind == 2) {
    out.ok = false;
    out.reason = shared->reason;
  }
  munmap(page, sizeof(Shared));
  return out;
}

void ReadMrptFile(const std::string& path, const std::string& what, const std::function<void()>& read) {
  RequireReadableFile(path);
  const auto fail = [&](const std::string& cause) {
    throw std::runtime_error(path + ": cannot read " + what + ": " + cause);
  };
  const MrptTrial trial = TrialReadMrpt(path, [&](uint64_t*) { read(); });
  if (!trial.ok) {
    if (trial.reason.rfind(path + ": ", 0) == 0) throw std::runtime_error(trial.reason);
    fail(trial.reason);
  }
  try {
    read();
  } catch (const std::exception& e) {
    const std::string text = e.what();
    if (text.rfind(path + ": ", 0) == 0) throw;  // already names the file
    fail(MrptReason(text));
  }
}

}  // namespace mbot::drivers
