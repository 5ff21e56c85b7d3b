// distributed/launcher_link.cpp — finds the rank's connection to the PMIx server
// and turns off Nagle's algorithm on it (why: launcher_link.h).
#include "distributed/launcher_link.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace tdpm::dist {

namespace {

bool peerOf(int fd, TcpEndpoint& out) {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) return false;
  out = TcpEndpoint{};
  if (a.ss_family == AF_INET) {
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(&a);
    out.family = AF_INET;
    std::memcpy(out.address.data(), &v4->sin_addr, 4);
    out.port = ntohs(v4->sin_port);
    return true;
  }
  if (a.ss_family == AF_INET6) {
    const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&a);
    out.family = AF_INET6;
    std::memcpy(out.address.data(), &v6->sin6_addr, 16);
    out.port = ntohs(v6->sin6_port);
    return true;
  }
  return false;
}

// Calls fn(fd) for every open file descriptor whose peer is one of `servers`.
template <class Fn>
int forEachConnectionTo(const std::vector<TcpEndpoint>& servers, Fn&& fn) {
  if (servers.empty()) return 0;
  DIR* dir = opendir("/proc/self/fd");
  if (!dir) return 0;
  std::vector<int> fds;
  while (dirent* e = readdir(dir)) {
    char* end = nullptr;
    long fd = std::strtol(e->d_name, &end, 10);
    if (end != e->d_name && *end == '\0' && fd >= 0) fds.push_back(int(fd));
  }
  closedir(dir);  // its own descriptor was in the list: it is closed now, getpeername fails on it
  int found = 0;
  for (int fd : fds) {
    TcpEndpoint peer;
    if (!peerOf(fd, peer)) continue;
    if (std::find(servers.begin(), servers.end(), peer) == servers.end()) continue;
    ++found;
    fn(fd);
  }
  return found;
}

}  // namespace

bool parsePmixServerUri(const std::string& uri, TcpEndpoint& out) {
  size_t at = uri.find("://");
  if (at == std::string::npos || at < 4) return false;
  const std::string scheme = uri.substr(at - 4, 4);
  if (scheme != "tcp4" && scheme != "tcp6") return false;
  std::string rest = uri.substr(at + 3);
  size_t colon = rest.rfind(':');
  if (colon == std::string::npos || colon + 1 >= rest.size()) return false;
  std::string host = rest.substr(0, colon), portText = rest.substr(colon + 1);
  char* end = nullptr;
  long port = std::strtol(portText.c_str(), &end, 10);
  if (*end != '\0' || port <= 0 || port > 65535) return false;
  TcpEndpoint e;
  e.port = uint16_t(port);
  if (scheme == "tcp4") {
    e.family = AF_INET;
    if (inet_pton(AF_INET, host.c_str(), e.address.data()) != 1) return false;
  } else {
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
    e.family = AF_INET6;
    if (inet_pton(AF_INET6, host.c_str(), e.address.data()) != 1) return false;
  }
  out = e;
  return true;
}

std::vector<TcpEndpoint> pmixServerEndpoints() {
  std::vector<TcpEndpoint> all;
  for (const char* name : {"PMIX_SERVER_URI41", "PMIX_SERVER_URI4", "PMIX_SERVER_URI3", "PMIX_SERVER_URI21",
                           "PMIX_SERVER_URI2"}) {
    const char* v = std::getenv(name);
    TcpEndpoint e;
    if (v && parsePmixServerUri(v, e) && std::find(all.begin(), all.end(), e) == all.end()) all.push_back(e);
  }
  return all;
}

int setNoDelayOnConnectionsTo(const std::vector<TcpEndpoint>& servers) {
  return forEachConnectionTo(servers, [](int fd) {
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // a failure only leaves the old latency
  });
}

int countConnectionsTo(const std::vector<TcpEndpoint>& servers, bool* allNoDelay) {
  bool all = true;
  int n = forEachConnectionTo(servers, [&](int fd) {
    int v = 0;
    socklen_t len = sizeof v;
    if (getsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &v, &len) != 0 || v == 0) all = false;
  });
  if (allNoDelay) *allNoDelay = all;
  return n;
}

}  // namespace tdpm::dist
