#pragma once
// Runs the relight executable as a child process under a wall-clock limit, for the robustness
// matrix. Unlike run_command.h (a shell line through std::system) it tells a crash from an exit
// (a shell reports a child killed by SIGSEGV as exit code 139, indistinguishable from exit(139)),
// kills a hung run instead of hanging the test, and can send SIGINT once a condition holds
// (Ctrl-C in the middle of a run). stdout and stderr go to files, so a chatty child never blocks
// on a full pipe; stdin is /dev/null.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "relight/core/atomic_file.h"
#include "temp_dir.h"

extern char** environ;

namespace relight::robustness {

struct BoundedRun {
  std::vector<std::string> arguments;              ///< after the relight executable
  std::chrono::seconds limit{60};                  ///< the run is killed (SIGKILL) after this
  std::map<std::string, std::string> environment;  ///< set or overridden in the child
  /// Polled every 20 ms while the child runs; SIGINT is sent once, the first time it returns true.
  std::function<bool()> interrupt_when;
};

struct RunOutcome {
  int exit_code = -1;      ///< valid when the child exited (signal == 0 and !timed_out)
  int signal = 0;          ///< the signal that killed the child, 0 when it exited
  bool timed_out = false;  ///< killed by us after BoundedRun::limit
  bool interrupted = false;  ///< SIGINT was sent
  double seconds = 0;
  double peak_rss_mb = 0;  ///< the child's peak resident memory (wait4's ru_maxrss)
  std::string out, err;
};

namespace detail {

inline std::vector<std::string> child_environment(const std::map<std::string, std::string>& overrides) {
  std::vector<std::string> entries;
  for (char** entry = environ; *entry != nullptr; ++entry) {
    const std::string text = *entry;
    if (!overrides.count(text.substr(0, text.find('=')))) entries.push_back(text);
  }
  for (const auto& [name, value] : overrides) entries.push_back(name + "=" + value);
  return entries;
}

inline std::vector<char*> pointers(std::vector<std::string>& strings) {
  std::vector<char*> result;
  for (auto& s : strings) result.push_back(s.data());
  result.push_back(nullptr);
  return result;
}

}  // namespace detail

inline RunOutcome run_relight(const BoundedRun& run) {
  test::TempDir capture;
  const std::string out_file = (capture.path() / "out").string(), err_file = (capture.path() / "err").string();
  std::vector<std::string> argv_strings{RELIGHT_BIN};
  argv_strings.insert(argv_strings.end(), run.arguments.begin(), run.arguments.end());
  std::vector<std::string> env_strings = detail::child_environment(run.environment);
  // Everything the child needs is prepared before fork: after it, only async-signal-safe calls.
  const auto argv = detail::pointers(argv_strings);
  const auto envp = detail::pointers(env_strings);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (in < 0 || out < 0 || err < 0) ::_exit(126);
    ::dup2(in, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::setpgid(0, 0);  // its own process group, so that the kill below reaches helpers it starts
    ::execve(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  RunOutcome outcome;
  int status = 0;
  struct rusage usage {};
  for (;;) {
    const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    if (std::chrono::steady_clock::now() - start > run.limit) {
      ::kill(-pid, SIGKILL);
      ::kill(pid, SIGKILL);
      ::wait4(pid, &status, 0, &usage);
      outcome.timed_out = true;
      break;
    }
    if (run.interrupt_when && !outcome.interrupted && run.interrupt_when()) {
      ::kill(pid, SIGINT);
      outcome.interrupted = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  outcome.peak_rss_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;
  if (!outcome.timed_out && WIFEXITED(status)) outcome.exit_code = WEXITSTATUS(status);
  if (!outcome.timed_out && WIFSIGNALED(status)) outcome.signal = WTERMSIG(status);
  outcome.out = read_text_file(out_file);
  outcome.err = read_text_file(err_file);
  return outcome;
}

inline RunOutcome run_relight(std::vector<std::string> arguments, std::chrono::seconds limit = std::chrono::seconds(60)) {
  BoundedRun run;
  run.arguments = std::move(arguments);
  run.limit = limit;
  return run_relight(run);
}

}  // namespace relight::robustness
