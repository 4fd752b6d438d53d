#include "engine/model_probe.h"

#include <assimp/Importer.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
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

// Sanitizers reserve terabytes of address space for their shadow memory, so a cap on it would
// stop the probe before it starts.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define BALLPIT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define BALLPIT_SANITIZED 1
#endif
#endif

namespace ballpit {

namespace {

#ifdef BALLPIT_SANITIZED
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

// The build tree's probe (engine/CMakeLists.txt).
constexpr const char* kBuiltProbe = BALLPIT_MODEL_PROBE_PATH;

// set_probe_program's, empty for kBuiltProbe.
std::mutex g_program_mutex;
std::string g_program;

// The most of assimp's message the importer keeps: it is one line, naming what it could not
// parse, and an error must stay readable whatever the file made of it.
constexpr std::size_t kMessageLimit = 1000;

// The probe's stdout, read as it writes, so that no message can fill the pipe and stall it.
class ProbeOutput {
 public:
  ProbeOutput() {
    if (pipe2(fd_, O_CLOEXEC) == 0) {
      fcntl(fd_[0], F_SETFL, O_NONBLOCK);
    } else {
      fd_[0] = fd_[1] = -1;  // no pipe: the probe writes to /dev/null, and a refusal gives no reason
    }
  }
  ProbeOutput(const ProbeOutput&) = delete;
  ProbeOutput& operator=(const ProbeOutput&) = delete;
  ~ProbeOutput() {
    for (int fd : fd_)
      if (fd >= 0) close(fd);
  }

  // Where the probe's stdout goes: the pipe (the dup2 clears its close-on-exec flag in the
  // probe), else /dev/null.
  void connect(posix_spawn_file_actions_t& actions) const {
    if (fd_[1] >= 0) posix_spawn_file_actions_adddup2(&actions, fd_[1], STDOUT_FILENO);
    else posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  }
  // After the spawn the write end is the probe's alone.
  void close_write_end() {
    if (fd_[1] >= 0) close(fd_[1]);
    fd_[1] = -1;
  }
  // Takes what the probe has written so far.
  void drain() {
    if (fd_[0] < 0) return;
    char chunk[4096];
    ssize_t got = 0;
    while ((got = read(fd_[0], chunk, sizeof chunk)) > 0) {
      const std::size_t room = kMessageLimit - std::min(kMessageLimit, text_.size());
      text_.append(chunk, std::min(room, static_cast<std::size_t>(got)));
    }
  }
  const std::string& text() const { return text_; }

 private:
  int fd_[2];
  std::string text_;
};

struct ProbeWait {
  enum { Finished, Running, Lost } state;
  int status = 0;  // waitpid's, when Finished
};

// Waits for the probe until `deadline`, taking its output as it comes. Lost: something else
// reaped it (SIGCHLD ignored), and its verdict with it.
ProbeWait wait_until(pid_t child, std::chrono::steady_clock::time_point deadline, ProbeOutput& output) {
  // Polled: a blocking waitpid has no deadline, and the probe's usual tens of milliseconds make
  // a few wake-ups, not a busy wait.
  std::chrono::milliseconds pause{1};
  while (true) {
    output.drain();
    int status = 0;
    const pid_t done = waitpid(child, &status, WNOHANG);
    if (done == child) {
      output.drain();  // all it wrote is in the pipe now
      return {ProbeWait::Finished, status};
    }
    if (done < 0 && errno != EINTR) return {ProbeWait::Lost};
    if (std::chrono::steady_clock::now() >= deadline) return {ProbeWait::Running};
    std::this_thread::sleep_for(pause);
    pause = std::min(2 * pause, std::chrono::milliseconds{20});
  }
}

[[noreturn]] void out_of_memory() { std::_Exit(kProbeOutOfMemory); }

}  // namespace

void fail_model_file(const std::string& path, const std::string& what) {
  throw Error("model file '" + path + "': " + what);
}

void set_probe_program(const std::string& program) {
  const std::lock_guard<std::mutex> lock(g_program_mutex);
  g_program = program;
}

std::string probe_program() {
  const std::lock_guard<std::mutex> lock(g_program_mutex);
  return g_program.empty() ? std::string(kBuiltProbe) : g_program;
}

bool probe_limits_memory() { return !kSanitized; }

void limit_probe_memory(std::size_t megabytes) {
  if (probe_limits_memory()) {
    const rlim_t bytes = static_cast<rlim_t>(megabytes) << 20;
    const rlimit limit{bytes, bytes};
    setrlimit(RLIMIT_AS, &limit);  // if refused (a lower hard limit), the lower one holds
  }
  // assimp allocates with new. Ended here, a refused allocation is told apart from a refused
  // file: assimp would catch the std::bad_alloc and refuse the file with only that name.
  std::set_new_handler(out_of_memory);
}

int read_in_probe(const char* path, unsigned flags) {
  Assimp::Importer importer;
  if (importer.ReadFile(path, flags) != nullptr) return kProbeRead;
  std::fputs(importer.GetErrorString(), stdout);
  std::fflush(stdout);
  return kProbeRefused;
}

void refuse_unless_assimp_reads_it(const std::string& path, unsigned flags, const ProbeSettings& probe) {
  const std::string program = probe.program.empty() ? probe_program() : probe.program;
  const std::string flag_text = std::to_string(flags), memory_text = std::to_string(probe.memory_limit_mb);
  char* const argv[] = {const_cast<char*>(program.c_str()), const_cast<char*>(flag_text.c_str()),
                        const_cast<char*>(memory_text.c_str()), const_cast<char*>(path.c_str()), nullptr};
  // stdout carries assimp's message; stderr is quiet: the importing process reports the outcome
  // (a sanitizer would print a crash report).
  ProbeOutput output;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  output.connect(actions);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t child = 0;
  const int spawned = posix_spawn(&child, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  output.close_write_end();
  if (spawned == ENOENT || spawned == EACCES) {
    fail_model_file(path, "cannot check it before reading: the model probe '" + program + "' " +
                              (spawned == ENOENT ? "is missing" : "cannot be run") + " (build the target ballpit-model-probe)");
  }
  if (spawned != 0) return;  // no process to spare (EAGAIN, ENOMEM): import directly, unchecked

  const ProbeWait wait = wait_until(child, std::chrono::steady_clock::now() + probe.time_limit, output);
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
  const int code = WIFEXITED(s) ? WEXITSTATUS(s) : -1;
  if (code == kProbeRead) return;
  if (code == kProbeRefused) {
    fail_model_file(path, "assimp cannot read it: " + (output.text().empty() ? std::string("it gave no reason") : output.text()));
  }
  if (code == kProbeOutOfMemory) {
    fail_model_file(path, "assimp needed more than " + memory_text +
                              " MB to read it: the file is damaged, or too large to animate");
  }
  if (code == kProbeUsage) {
    fail_model_file(path, "the model probe '" + program + "' refused how it was started (" + flag_text + " " +
                              memory_text + " " + path + ")");
  }
  const std::string how = WIFSIGNALED(s) ? std::string(strsignal(WTERMSIG(s))) : "exit status " + std::to_string(code);
  fail_model_file(path, "assimp crashed reading it (" + how + "): the file is damaged");
}

}  // namespace ballpit
