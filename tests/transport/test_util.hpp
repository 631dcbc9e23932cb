#pragma once
// Shared helpers for the transport tests: temp dirs, endpoints, child processes.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "angio/transport/session.hpp"

namespace angio::transport::test {

// Fresh short directory under /tmp (unix socket paths are limited to 107 bytes), removed
// with its content on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string unix_endpoint(const std::string& name = "t.sock") const;

 private:
  std::filesystem::path path_;
};

// A tcp endpoint on 127.0.0.1 with a port that was free a moment ago.
std::string free_tcp_endpoint();

// Two sessions of this process linked through `endpoint`: the first listens on it, the second
// connects to it.
std::pair<Session, Session> linked_sessions(const std::string& endpoint);

// Unique key prefix so concurrent test runs never see each other's keys.
std::string unique_prefix(const std::string& test_name);

// Child process started with posix_spawn; killed (SIGKILL) and reaped on destruction if
// still running.
class ChildProcess {
 public:
  explicit ChildProcess(const std::vector<std::string>& argv);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  // Waits for exit; returns the exit code, -signal if killed, or -1000 on timeout.
  int wait_exit(std::chrono::milliseconds timeout);
  void kill_now();

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
};

constexpr int kWaitTimedOut = -1000;

}  // namespace angio::transport::test
