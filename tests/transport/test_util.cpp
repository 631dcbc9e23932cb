#include "test_util.hpp"

#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace angio::transport::test {

TempDir::TempDir() {
  std::string tmpl = "/tmp/angio-tp-XXXXXX";
  if (!mkdtemp(tmpl.data())) throw std::runtime_error(std::string("mkdtemp: ") + std::strerror(errno));
  path_ = tmpl;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string TempDir::unix_endpoint(const std::string& name) const {
  return "unixsock-stream/" + (path_ / name).string();
}

std::string free_tcp_endpoint() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("socket() failed");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof(addr);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
    ::close(fd);
    throw std::runtime_error("cannot find a free tcp port");
  }
  const int port = ntohs(addr.sin_port);
  ::close(fd);
  return "tcp/127.0.0.1:" + std::to_string(port);
}

std::pair<Session, Session> linked_sessions(const std::string& endpoint) {
  auto listener = Session::open({.listen = {endpoint}, .connect = {}});
  return {std::move(listener), Session::open({.listen = {}, .connect = {endpoint}})};
}

std::string unique_prefix(const std::string& test_name) {
  static std::atomic<int> counter{0};
  return "angio/test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "/" + test_name;
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const int rc = ::posix_spawn(&pid_, args[0], nullptr, nullptr, args.data(), environ);
  if (rc != 0) throw std::runtime_error("posix_spawn " + argv[0] + ": " + std::strerror(rc));
}

ChildProcess::~ChildProcess() {
  if (!reaped_) {
    kill_now();
    wait_exit(std::chrono::seconds(10));
  }
}

void ChildProcess::kill_now() {
  if (!reaped_ && pid_ > 0) ::kill(pid_, SIGKILL);
}

int ChildProcess::wait_exit(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      reaped_ = true;
      if (WIFEXITED(status)) return WEXITSTATUS(status);
      if (WIFSIGNALED(status)) return -WTERMSIG(status);
      return -1;
    }
    if (r < 0) {
      reaped_ = true;
      return -1;
    }
    if (std::chrono::steady_clock::now() >= deadline) return kWaitTimedOut;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace angio::transport::test
