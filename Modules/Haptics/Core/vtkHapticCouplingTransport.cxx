// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticCouplingTransport.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#if defined(_WIN32)
#ifndef NOMINMAX
#define NOMINMAX // windows.h's min and max macros would break std::min and std::max
#endif
#include <winsock2.h>
#include <ws2tcpip.h>
#else
#include <arpa/inet.h>
#include <cerrno>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#endif

vtkStandardNewMacro(vtkHapticCouplingTransport);

namespace
{
#if defined(_WIN32)
using SocketHandle = SOCKET;
const SocketHandle InvalidSocket = INVALID_SOCKET;
void CloseSocket(SocketHandle handle)
{
  closesocket(handle);
}
bool WouldBlock()
{
  const int error = WSAGetLastError();
  return error == WSAEWOULDBLOCK || error == WSAECONNRESET;
}
bool MakeNonBlocking(SocketHandle handle)
{
  u_long on = 1;
  return ioctlsocket(handle, FIONBIO, &on) == 0;
}
#else
using SocketHandle = int;
const SocketHandle InvalidSocket = -1;
void CloseSocket(SocketHandle handle)
{
  close(handle);
}
bool WouldBlock()
{
  // A peer that is not listening yet makes loopback report refusals: nothing to read either.
  return errno == EAGAIN || errno == EWOULDBLOCK || errno == ECONNREFUSED || errno == EINTR;
}
bool MakeNonBlocking(SocketHandle handle)
{
  const int flags = fcntl(handle, F_GETFL, 0);
  return flags >= 0 && fcntl(handle, F_SETFL, flags | O_NONBLOCK) == 0;
}
#endif

const unsigned char Magic[4] = { 'V', 'C', 'H', 'C' };
constexpr int ChecksumOffset = vtkHapticCouplingTransport::PacketSize - 4;

/// CRC-32 (IEEE 802.3, reflected 0xEDB88320), the checksum zlib and Ethernet use.
const std::array<std::uint32_t, 256>& CRCTable()
{
  static const std::array<std::uint32_t, 256> table = []() {
    std::array<std::uint32_t, 256> entries{};
    for (std::uint32_t n = 0; n < 256; ++n)
    {
      std::uint32_t value = n;
      for (int bit = 0; bit < 8; ++bit)
      {
        value = (value & 1u) ? (0xEDB88320u ^ (value >> 1)) : (value >> 1);
      }
      entries[n] = value;
    }
    return entries;
  }();
  return table;
}

std::uint32_t CRC32(const unsigned char* bytes, int size)
{
  const std::array<std::uint32_t, 256>& table = CRCTable();
  std::uint32_t crc = 0xFFFFFFFFu;
  for (int n = 0; n < size; ++n)
  {
    crc = table[(crc ^ bytes[n]) & 0xFFu] ^ (crc >> 8);
  }
  return crc ^ 0xFFFFFFFFu;
}

void PutUnsigned(unsigned char* at, std::uint64_t value, int bytes)
{
  for (int n = 0; n < bytes; ++n)
  {
    at[n] = static_cast<unsigned char>((value >> (8 * n)) & 0xFFu);
  }
}

std::uint64_t GetUnsigned(const unsigned char* at, int bytes)
{
  std::uint64_t value = 0;
  for (int n = 0; n < bytes; ++n)
  {
    value |= static_cast<std::uint64_t>(at[n]) << (8 * n);
  }
  return value;
}

void PutDouble(unsigned char* at, double value)
{
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  PutUnsigned(at, bits, 8);
}

double GetDouble(const unsigned char* at)
{
  const std::uint64_t bits = GetUnsigned(at, 8);
  double value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

/// A packet waiting for its injected delay.
struct Delayed
{
  double Due;
  unsigned char Bytes[vtkHapticCouplingTransport::PacketSize];
};
} // namespace

struct vtkHapticCouplingTransport::Internals
{
  SocketHandle Socket = InvalidSocket;
  sockaddr_in Remote{};
  // Listening: the packets of which host are accepted (INADDR_ANY: any), and whether Remote holds a peer yet.
  bool Listening = false;
  std::uint32_t ListenFrom = 0;
  bool PeerAddressKnown = false;
  // Remote's address and port (address << 16 | port; 0: none) for readers on other threads.
  std::atomic<std::uint64_t> PublishedPeer{ 0 };
  int LocalPort = 0;
  unsigned int Session = 0;
  unsigned long long NextSequence = 1;
  bool WinsockStarted = false;

  // The peer as accepted so far.
  bool HavePeer = false;
  unsigned int PeerSession = 0;
  unsigned long long PeerSequence = 0;
  double LastAccepted = 0.0;

  // Injection: xorshift64* state and a FIFO of delayed packets (constant delay keeps it ordered).
  std::uint64_t Random = 1;
  std::vector<Delayed> Queue;
  size_t QueueHead = 0;
  size_t QueueCount = 0;

  std::atomic<unsigned long long> Sent{ 0 };
  std::atomic<unsigned long long> Lost{ 0 };
  std::atomic<unsigned long long> SendFailures{ 0 };
  std::atomic<unsigned long long> Accepted{ 0 };
  std::atomic<unsigned long long> Garbled{ 0 };
  std::atomic<unsigned long long> Stale{ 0 };
  std::atomic<unsigned long long> ForeignSession{ 0 };
  std::atomic<unsigned long long> ForeignHost{ 0 };
  std::atomic<unsigned long long> FrameMismatches{ 0 };
  std::atomic<unsigned long long> LastRefusedFrame{ 0 };

  /// Uniform in [0, 1).
  double NextRandom()
  {
    this->Random ^= this->Random >> 12;
    this->Random ^= this->Random << 25;
    this->Random ^= this->Random >> 27;
    return static_cast<double>((this->Random * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
  }

  void PublishPeer()
  {
    this->PublishedPeer.store(
      (static_cast<std::uint64_t>(ntohl(this->Remote.sin_addr.s_addr)) << 16) | ntohs(this->Remote.sin_port),
      std::memory_order_release);
  }

  bool Write(const unsigned char* bytes)
  {
    if (!this->PeerAddressKnown)
    {
      return false; // listening, and nobody has joined yet: nowhere to send
    }
    const auto written = sendto(this->Socket, reinterpret_cast<const char*>(bytes), PacketSize, 0,
      reinterpret_cast<const sockaddr*>(&this->Remote), sizeof(this->Remote));
    if (written != PacketSize)
    {
      this->SendFailures.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    this->Sent.fetch_add(1, std::memory_order_relaxed);
    return true;
  }

  void WriteDue(double now)
  {
    while (this->QueueCount > 0 && this->Queue[this->QueueHead].Due <= now)
    {
      this->Write(this->Queue[this->QueueHead].Bytes);
      this->QueueHead = (this->QueueHead + 1) % this->Queue.size();
      --this->QueueCount;
    }
  }
};

//------------------------------------------------------------------------------
vtkHapticCouplingTransport::vtkHapticCouplingTransport()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkHapticCouplingTransport::~vtkHapticCouplingTransport()
{
  this->Close();
}

//------------------------------------------------------------------------------
void vtkHapticCouplingTransport::EncodePacket(const State& state, unsigned char packet[PacketSize])
{
  std::memset(packet, 0, PacketSize);
  std::memcpy(packet, Magic, 4);
  packet[4] = static_cast<unsigned char>(ProtocolVersion);
  packet[5] = static_cast<unsigned char>(state.Flags & 0xFFu);
  PutUnsigned(packet + 8, state.Session, 4);
  PutUnsigned(packet + 12, state.Sequence, 8);
  PutDouble(packet + 20, state.Time);
  for (int axis = 0; axis < 3; ++axis)
  {
    PutDouble(packet + 28 + 8 * axis, state.Position[axis]);
    PutDouble(packet + 52 + 8 * axis, state.Velocity[axis]);
  }
  PutDouble(packet + 76, state.EnergySent);
  PutDouble(packet + 84, state.Tank);
  PutUnsigned(packet + 92, state.Frame, 8);
  PutUnsigned(packet + ChecksumOffset, CRC32(packet, ChecksumOffset), 4);
}

//------------------------------------------------------------------------------
bool vtkHapticCouplingTransport::DecodePacket(const unsigned char* packet, int size, State& state)
{
  if (!packet || size != PacketSize || std::memcmp(packet, Magic, 4) != 0 || packet[4] != ProtocolVersion ||
    GetUnsigned(packet + ChecksumOffset, 4) != CRC32(packet, ChecksumOffset))
  {
    return false;
  }
  State decoded;
  decoded.Flags = packet[5];
  decoded.Session = static_cast<unsigned int>(GetUnsigned(packet + 8, 4));
  decoded.Sequence = GetUnsigned(packet + 12, 8);
  decoded.Time = GetDouble(packet + 20);
  bool finite = std::isfinite(decoded.Time);
  for (int axis = 0; axis < 3; ++axis)
  {
    decoded.Position[axis] = GetDouble(packet + 28 + 8 * axis);
    decoded.Velocity[axis] = GetDouble(packet + 52 + 8 * axis);
    finite = finite && std::isfinite(decoded.Position[axis]) && std::isfinite(decoded.Velocity[axis]);
  }
  decoded.EnergySent = GetDouble(packet + 76);
  decoded.Tank = GetDouble(packet + 84);
  decoded.Frame = GetUnsigned(packet + 92, 8);
  // A valid checksum over nonsense (a buggy or hostile sender) is refused as well.
  if (!finite || !std::isfinite(decoded.Tank) || !std::isfinite(decoded.EnergySent) || decoded.EnergySent < 0.0 ||
    decoded.Session == 0 || decoded.Sequence == 0)
  {
    return false;
  }
  state = decoded;
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticCouplingTransport::Open(const char* localHost, int localPort, const char* remoteHost, int remotePort)
{
  this->Close();
  Internals& internal = *this->Internal;
  if (!localHost || !remoteHost || localPort < 0 || localPort > 65535 || remotePort < 0 || remotePort > 65535)
  {
    vtkErrorMacro("Open: hosts are required and ports must be 0-65535 (local 0: any free port; remote 0: listen)");
    return false;
  }
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_port = htons(static_cast<unsigned short>(localPort));
  sockaddr_in remote{};
  remote.sin_family = AF_INET;
  remote.sin_port = htons(static_cast<unsigned short>(remotePort));
  if (inet_pton(AF_INET, localHost, &local.sin_addr) != 1 || inet_pton(AF_INET, remoteHost, &remote.sin_addr) != 1)
  {
    vtkErrorMacro("Open: '" << localHost << "' or '" << remoteHost << "' is not a numeric IPv4 address (e.g. 127.0.0.1)");
    return false;
  }
#if defined(_WIN32)
  WSADATA data;
  if (WSAStartup(MAKEWORD(2, 2), &data) != 0)
  {
    vtkErrorMacro("Open: Winsock could not be started");
    return false;
  }
  internal.WinsockStarted = true;
#endif
  internal.Socket = socket(AF_INET, SOCK_DGRAM, 0);
  if (internal.Socket == InvalidSocket)
  {
    vtkErrorMacro("Open: no UDP socket could be made");
    this->Close();
    return false;
  }
  if (!MakeNonBlocking(internal.Socket))
  {
    vtkErrorMacro("Open: the socket could not be made non-blocking");
    this->Close();
    return false;
  }
  if (bind(internal.Socket, reinterpret_cast<const sockaddr*>(&local), sizeof(local)) != 0)
  {
    vtkErrorMacro("Open: port " << localPort << " on " << localHost << " could not be bound (in use?)");
    this->Close();
    return false;
  }
  sockaddr_in bound{};
  socklen_t length = sizeof(bound);
  getsockname(internal.Socket, reinterpret_cast<sockaddr*>(&bound), &length);
  internal.LocalPort = ntohs(bound.sin_port);
  internal.Remote = remote;
  internal.Listening = remotePort == 0;
  internal.ListenFrom = remote.sin_addr.s_addr;
  internal.PeerAddressKnown = !internal.Listening;
  if (internal.PeerAddressKnown)
  {
    internal.PublishPeer();
  }
  else
  {
    internal.PublishedPeer.store(0, std::memory_order_release);
  }

  std::random_device device;
  const auto ticks = static_cast<unsigned int>(std::chrono::steady_clock::now().time_since_epoch().count());
  internal.Session = (device() ^ ticks) | 1u;
  internal.NextSequence = 1;
  internal.HavePeer = false;
  internal.PeerSession = 0;
  internal.PeerSequence = 0;
  internal.LastAccepted = 0.0;
  this->SetInjectionSeed(this->InjectionSeed);
  // Room for the longest injected delay at 4 kHz, allocated here, not in a tick.
  internal.Queue.assign(4096, Delayed{});
  internal.QueueHead = internal.QueueCount = 0;
  for (auto* counter : { &internal.Sent, &internal.Lost, &internal.SendFailures, &internal.Accepted, &internal.Garbled,
         &internal.Stale, &internal.ForeignSession, &internal.ForeignHost, &internal.FrameMismatches, &internal.LastRefusedFrame })
  {
    counter->store(0);
  }
  CRCTable();
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticCouplingTransport::Close()
{
  Internals& internal = *this->Internal;
  if (internal.Socket != InvalidSocket)
  {
    CloseSocket(internal.Socket);
    internal.Socket = InvalidSocket;
  }
#if defined(_WIN32)
  if (internal.WinsockStarted)
  {
    WSACleanup();
  }
#endif
  internal.WinsockStarted = false;
  internal.LocalPort = 0;
  internal.PeerAddressKnown = false;
  internal.PublishedPeer.store(0, std::memory_order_release);
  internal.QueueCount = 0;
}

//------------------------------------------------------------------------------
bool vtkHapticCouplingTransport::IsOpen() const
{
  return this->Internal->Socket != InvalidSocket;
}

//------------------------------------------------------------------------------
int vtkHapticCouplingTransport::GetLocalPort() const
{
  return this->Internal->LocalPort;
}

//------------------------------------------------------------------------------
unsigned int vtkHapticCouplingTransport::GetSession() const
{
  return this->Internal->Session;
}

//------------------------------------------------------------------------------
bool vtkHapticCouplingTransport::IsListening() const
{
  return this->Internal->Listening;
}

//------------------------------------------------------------------------------
std::string vtkHapticCouplingTransport::GetPeerAddress() const
{
  const std::uint64_t peer = this->Internal->PublishedPeer.load(std::memory_order_acquire);
  if (peer == 0)
  {
    return std::string();
  }
  const auto address = static_cast<std::uint32_t>(peer >> 16);
  return std::to_string(address >> 24) + "." + std::to_string((address >> 16) & 0xFFu) + "." +
    std::to_string((address >> 8) & 0xFFu) + "." + std::to_string(address & 0xFFu) + ":" +
    std::to_string(peer & 0xFFFFu);
}

//------------------------------------------------------------------------------
void vtkHapticCouplingTransport::SetInjectionSeed(unsigned long long seed)
{
  this->InjectionSeed = seed;
  // splitmix64 spreads any seed (0 included) over the generator's state, never 0.
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  this->Internal->Random = z ? z : 1;
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkHapticCouplingTransport::Send(State& state, double now)
{
  Internals& internal = *this->Internal;
  if (internal.Socket == InvalidSocket)
  {
    return false;
  }
  state.Session = internal.Session;
  state.Sequence = internal.NextSequence++;
  state.Frame = this->FrameFingerprint;
  internal.WriteDue(now);
  if (this->InjectedLossRate > 0.0 && internal.NextRandom() < this->InjectedLossRate)
  {
    internal.Lost.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  if (this->InjectedDelay <= 0.0)
  {
    unsigned char packet[PacketSize];
    EncodePacket(state, packet);
    return internal.Write(packet);
  }
  if (internal.QueueCount == internal.Queue.size())
  {
    internal.SendFailures.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  Delayed& slot = internal.Queue[(internal.QueueHead + internal.QueueCount) % internal.Queue.size()];
  slot.Due = now + this->InjectedDelay;
  EncodePacket(state, slot.Bytes);
  ++internal.QueueCount;
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticCouplingTransport::SendRawDatagram(const unsigned char* bytes, int size)
{
  Internals& internal = *this->Internal;
  if (internal.Socket == InvalidSocket || !internal.PeerAddressKnown || !bytes || size < 0 || size > 65507)
  {
    return false;
  }
  const auto written = sendto(internal.Socket, reinterpret_cast<const char*>(bytes), size, 0,
    reinterpret_cast<const sockaddr*>(&internal.Remote), sizeof(internal.Remote));
  return written == size;
}

//------------------------------------------------------------------------------
bool vtkHapticCouplingTransport::ReceiveLatest(double now, State& latest)
{
  Internals& internal = *this->Internal;
  if (internal.Socket == InvalidSocket)
  {
    return false;
  }
  internal.WriteDue(now);
  bool received = false;
  // Bounded: a flood cannot hold the tick; what is left waits for the next
  // one. The peer sends one a tick, so 32 leave ample room to catch up.
  for (int n = 0; n < 32; ++n)
  {
    unsigned char buffer[512];
    sockaddr_in from{};
    socklen_t fromLength = sizeof(from);
    const auto size = recvfrom(internal.Socket, reinterpret_cast<char*>(buffer), sizeof(buffer), 0,
      reinterpret_cast<sockaddr*>(&from), &fromLength);
    if (size < 0)
    {
      if (WouldBlock())
      {
        break;
      }
      continue;
    }
    // Listening, a packet from another address than the peer's may replace a peer silent for SessionTimeout.
    const bool peerSilent = !internal.HavePeer || now - internal.LastAccepted >= this->SessionTimeout;
    const bool fromPeer = from.sin_family == AF_INET && internal.PeerAddressKnown &&
      from.sin_addr.s_addr == internal.Remote.sin_addr.s_addr &&
      (!internal.Listening || from.sin_port == internal.Remote.sin_port);
    const bool mayJoin = internal.Listening && from.sin_family == AF_INET && peerSilent &&
      (internal.ListenFrom == htonl(INADDR_ANY) || from.sin_addr.s_addr == internal.ListenFrom);
    if (!fromPeer && !mayJoin)
    {
      internal.ForeignHost.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    State state;
    if (!DecodePacket(buffer, static_cast<int>(size), state))
    {
      internal.Garbled.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (state.Frame != this->FrameFingerprint)
    {
      // Positions in another frame (another scan, or a free device's millimetres) mean other places: never a peer.
      internal.FrameMismatches.fetch_add(1, std::memory_order_relaxed);
      internal.LastRefusedFrame.store(state.Frame, std::memory_order_relaxed);
      if (!fromPeer && !internal.HavePeer)
      {
        // Listening, nobody joined yet: answer it, so that the joining side hears this frame and can say why it is
        // refused rather than wait for an answer that never comes. It still never becomes the peer.
        internal.Remote = from;
        internal.PeerAddressKnown = true;
        internal.PublishPeer();
      }
      continue;
    }
    if (internal.HavePeer && state.Session != internal.PeerSession)
    {
      // Another session: the peer restarted, or someone else talks. Only a silent peer gives way.
      if (now - internal.LastAccepted < this->SessionTimeout)
      {
        internal.ForeignSession.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      internal.HavePeer = false;
    }
    if (internal.HavePeer && state.Sequence <= internal.PeerSequence)
    {
      internal.Stale.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (!fromPeer)
    {
      // The side that joins (or joins again from a new address): replies go where it sends from.
      internal.Remote = from;
      internal.PeerAddressKnown = true;
      internal.PublishPeer();
    }
    internal.HavePeer = true;
    internal.PeerSession = state.Session;
    internal.PeerSequence = state.Sequence;
    internal.LastAccepted = now;
    internal.Accepted.fetch_add(1, std::memory_order_relaxed);
    latest = state;
    received = true;
  }
  return received;
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticCouplingTransport::GetNumberOfPacketsSent() const
{
  return this->Internal->Sent.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfPacketsLostByInjection() const
{
  return this->Internal->Lost.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfSendFailures() const
{
  return this->Internal->SendFailures.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfPacketsAccepted() const
{
  return this->Internal->Accepted.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfGarbledPackets() const
{
  return this->Internal->Garbled.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfStalePackets() const
{
  return this->Internal->Stale.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfForeignSessionPackets() const
{
  return this->Internal->ForeignSession.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfForeignHostPackets() const
{
  return this->Internal->ForeignHost.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetNumberOfFrameMismatches() const
{
  return this->Internal->FrameMismatches.load(std::memory_order_relaxed);
}

unsigned long long vtkHapticCouplingTransport::GetLastRefusedFrame() const
{
  return this->Internal->LastRefusedFrame.load(std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticCouplingTransport::ComputeFrameFingerprint(vtkImageData* anatomy, vtkMatrix4x4* ijkToRAS)
{
  vtkDataArray* scalars = anatomy ? anatomy->GetPointData()->GetScalars() : nullptr;
  if (!scalars || !ijkToRAS)
  {
    return 0;
  }
  // FNV-1a, 64 bits: the same bytes give the same value on every platform (all fields little-endian here).
  std::uint64_t hash = 0xCBF29CE484222325ull;
  const auto mix = [&hash](const unsigned char* bytes, size_t count) {
    for (size_t n = 0; n < count; ++n)
    {
      hash = (hash ^ bytes[n]) * 0x100000001B3ull;
    }
  };
  const auto mixUnsigned = [&mix](std::uint64_t value) {
    unsigned char bytes[8];
    PutUnsigned(bytes, value, 8);
    mix(bytes, 8);
  };
  int dimensions[3];
  anatomy->GetDimensions(dimensions);
  for (int axis = 0; axis < 3; ++axis)
  {
    mixUnsigned(static_cast<std::uint64_t>(dimensions[axis]));
  }
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      // -0 and +0 are the same placement.
      const double value = ijkToRAS->GetElement(row, column) + 0.0;
      std::uint64_t bits;
      std::memcpy(&bits, &value, sizeof(bits));
      mixUnsigned(bits);
    }
  }
  mixUnsigned(static_cast<std::uint64_t>(scalars->GetDataType()));
  mixUnsigned(static_cast<std::uint64_t>(scalars->GetNumberOfComponents()));
  const size_t size = static_cast<size_t>(scalars->GetNumberOfValues()) * static_cast<size_t>(scalars->GetDataTypeSize());
  mix(static_cast<const unsigned char*>(scalars->GetVoidPointer(0)), size);
  return hash != 0 ? hash : 1;
}

//------------------------------------------------------------------------------
void vtkHapticCouplingTransport::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Open: " << (this->IsOpen() ? "yes" : "no") << "\n";
  os << indent << "LocalPort: " << this->GetLocalPort() << "\n";
  os << indent << "Listening: " << (this->IsListening() ? "yes" : "no") << "\n";
  os << indent << "PeerAddress: " << this->GetPeerAddress() << "\n";
  os << indent << "FrameFingerprint: " << this->FrameFingerprint << "\n";
  os << indent << "FrameMismatches: " << this->GetNumberOfFrameMismatches() << "\n";
  os << indent << "SessionTimeout: " << this->SessionTimeout << " s\n";
  os << indent << "InjectedDelay: " << this->InjectedDelay << " s\n";
  os << indent << "InjectedLossRate: " << this->InjectedLossRate << "\n";
  os << indent << "InjectionSeed: " << this->InjectionSeed << "\n";
  os << indent << "PacketsSent: " << this->GetNumberOfPacketsSent() << "\n";
  os << indent << "PacketsAccepted: " << this->GetNumberOfPacketsAccepted() << "\n";
}
