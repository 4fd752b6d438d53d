#include "engine/model_probe.h"

#include <assimp/Importer.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "engine/error.h"

// Debian builds assimp with ASSIMP_BUILD_DEBUG, so its internal checks (ai_assert) are live, and
// a failed one prints a line and aborts the whole process: a malformed model file (fuzzing found
// a .X file whose faces break the triangulation's count) would take the app down. This
// definition replaces the library's own: the executable's symbol is found first, and assimp
// 5.2 offers no handler to set instead. It throws, Importer::ReadFile's catch-all turns that
// into a failed import with this message, and import_model reports it naming the file. It lives
// here because every program that reads a model links this file: the app, the tests and the
// probe itself.
// (The library's signature, declared by <assimp/ai_assert.h> only under ASSIMP_BUILD_DEBUG.)
namespace Assimp {
[[noreturn]] void aiAssertViolation(const char* expression, const char* file, int line);
void aiAssertViolation(const char* expression, const char* file, int line) {
  throw std::runtime_error(std::string("an internal check failed (") + expression + ", " + file + ":" +
                           std::to_string(line) + ")");
}
}  // namespace Assimp

namespace ballpit {

namespace {

// The build tree's probe (engine/CMakeLists.txt).
constexpr const char* kBuiltProbe = BALLPIT_MODEL_PROBE_PATH;

struct ProbeWait {
  enum { Finished, Running, Lost } state;
  int status = 0;  // waitpid's, when Finished
};

// Waits for the probe until `deadline`. Lost: something else reaped it (SIGCHLD ignored), and
// its verdict with it.
ProbeWait wait_until(pid_t child, std::chrono::steady_clock::time_point deadline) {
  // Polled: a blocking waitpid has no deadline, and the probe's usual tens of milliseconds make
  // a few wake-ups, not a busy wait.
  std::chrono::milliseconds pause{1};
  while (true) {
    int status = 0;
    const pid_t done = waitpid(child, &status, WNOHANG);
    if (done == child) return {ProbeWait::Finished, status};
    if (done < 0 && errno != EINTR) return {ProbeWait::Lost};
    if (std::chrono::steady_clock::now() >= deadline) return {ProbeWait::Running};
    std::this_thread::sleep_for(pause);
    pause = std::min(2 * pause, std::chrono::milliseconds{20});
  }
}

}  // namespace

void fail_model_file(const std::string& path, const std::string& what) {
  throw Error("model file '" + path + "': " + what);
}

int read_in_probe(const char* path, unsigned flags) {
  Assimp::Importer importer;
  return importer.ReadFile(path, flags) != nullptr ? kProbeRead : kProbeRefused;
}

void refuse_if_it_crashes_assimp(const std::string& path, unsigned flags, const ProbeSettings& probe) {
  const std::string program = probe.program.empty() ? kBuiltProbe : probe.program;
  const std::string flag_text = std::to_string(flags);
  char* const argv[] = {const_cast<char*>(program.c_str()), const_cast<char*>(flag_text.c_str()),
                        const_cast<char*>(path.c_str()), nullptr};
  // Quiet: the importing process reports the outcome (a sanitizer would print a crash report).
  posix_spawn_file_actions_t quiet;
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&quiet, STDOUT_FILENO, STDERR_FILENO);
  pid_t child = 0;
  const int spawned = posix_spawn(&child, program.c_str(), &quiet, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&quiet);
  if (spawned == ENOENT || spawned == EACCES) {
    fail_model_file(path, "cannot check it before reading: the model probe '" + program + "' " +
                              (spawned == ENOENT ? "is missing" : "cannot be run") + " (build the target ballpit-model-probe)");
  }
  if (spawned != 0) return;  // no process to spare (EAGAIN, ENOMEM): import directly, unchecked

  const ProbeWait wait = wait_until(child, std::chrono::steady_clock::now() + probe.time_limit);
  if (wait.state == ProbeWait::Lost) return;  // no verdict: import directly, unchecked
  if (wait.state == ProbeWait::Running) {
    kill(child, SIGKILL);
    waitpid(child, nullptr, 0);
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g s", std::chrono::duration<double>(probe.time_limit).count());
    fail_model_file(path, std::string("assimp did not finish reading it within ") + limit +
                              ": the file is damaged, or too large to animate");
  }
  const int s = wait.status;
  if (WIFEXITED(s) && (WEXITSTATUS(s) == kProbeRead || WEXITSTATUS(s) == kProbeRefused)) return;
  if (WIFEXITED(s) && WEXITSTATUS(s) == kProbeUsage) {
    fail_model_file(path, "the model probe '" + program + "' refused how it was started (" + flag_text + " " + path +
                              ")");
  }
  const std::string how = WIFSIGNALED(s) ? std::string(strsignal(WTERMSIG(s))) : "exit status " + std::to_string(WEXITSTATUS(s));
  fail_model_file(path, "assimp crashed reading it (" + how + "): the file is damaged");
}

}  // namespace ballpit
