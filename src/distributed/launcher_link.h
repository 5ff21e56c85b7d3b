// distributed/launcher_link.h — the TCP connection between a rank and its
// launcher's PMIx server (Open MPI's mpirun / orted, or any PMIx launcher),
// found from the launcher's environment (PMIX_SERVER_URI*), and Nagle's
// algorithm turned off on it.
//
// Why: PMIx 4 talks to its server over TCP on the loopback interface
// without TCP_NODELAY. MPI_Finalize sends four small messages in a row
// right after one the server has not acknowledged yet (Linux delays an
// acknowledgement by up to 40 ms), so Nagle holds them back until that
// acknowledgement comes: every rank's MPI_Finalize took 45-60 ms, 40 of
// them asleep (strace of a trivial Init/Finalize job; docs/distributed.md).
// With TCP_NODELAY on the rank's end it takes 3-9 ms. The setting changes
// when bytes leave, never which bytes: the protocol is untouched.
// No mpi.h here; Linux-only (/proc/self/fd), elsewhere a no-op.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace tdpm::dist {

// A TCP endpoint: IPv4 or IPv6 address (bytes in network order) and port.
struct TcpEndpoint {
  int family = 0;  // AF_INET or AF_INET6
  std::array<uint8_t, 16> address{};
  uint16_t port = 0;
  bool operator==(const TcpEndpoint& o) const {
    return family == o.family && address == o.address && port == o.port;
  }
};

// The endpoint of a PMIx server URI ("<nspace>.<rank>;tcp4://127.0.0.1:51875"
// or ";tcp6://[::1]:51875"); false when it is not a TCP URI of that form.
bool parsePmixServerUri(const std::string& uri, TcpEndpoint& out);

// Every distinct endpoint named by PMIX_SERVER_URI41, _URI4, _URI3, _URI21
// and _URI2 in this process's environment (empty when not under PMIx).
std::vector<TcpEndpoint> pmixServerEndpoints();

// Sets TCP_NODELAY on every socket of this process whose peer is one of
// `servers`; returns how many such sockets it found.
int setNoDelayOnConnectionsTo(const std::vector<TcpEndpoint>& servers);

// How many sockets of this process have a peer in `servers`; *allNoDelay
// tells whether every one of them has TCP_NODELAY set (tests).
int countConnectionsTo(const std::vector<TcpEndpoint>& servers, bool* allNoDelay);

}  // namespace tdpm::dist
