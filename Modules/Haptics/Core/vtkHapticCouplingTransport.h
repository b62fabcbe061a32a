// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticCouplingTransport
 * @brief   The UDP link between two coupled haptic loops: latest state wins.
 *
 * Forces forwarded between an instructor's and a trainee's haptic loop need
 * their own 1 kHz stream, not OpenIGTLink: one small datagram per tick each
 * way. Each packet carries the sender's proxy state and the energy it has
 * shipped so far (vtkHapticCoupling), in a versioned layout (State, 104
 * bytes, little-endian) ending with a CRC-32 of everything before it.
 *
 * The frame the positions are in: each packet carries the sender's
 * FrameFingerprint, 0 for a device's own millimetres (two free devices) or
 * ComputeFrameFingerprint of the scan whose RAS millimetres both drilling
 * sessions share. A valid packet with another fingerprint than this side's
 * is refused and counted (the two sides drill different scans, or one
 * drills and the other holds a free device): its positions mean other
 * places, so no spring may act on them.
 *
 * Never blocks the tick: the socket is non-blocking; Send gives up (counted)
 * rather than wait for buffer space, ReceiveLatest drains what arrived and
 * keeps only the newest valid packet. A packet is dropped, and counted by
 * reason, when it is garbled (size, magic, version, checksum, non-finite or
 * negative fields), stale (a sequence number not above the last accepted
 * one of the same session: reordered, duplicated or replayed), from another
 * session while the current peer is alive (SessionTimeout), or from a host
 * other than the peer's.
 *
 * Fault injection, for tests and rehearsals: outgoing packets can be lost at
 * InjectedLossRate (a deterministic generator seeded by InjectionSeed) and
 * held for InjectedDelay seconds of the caller's clock before they are
 * written, in a queue allocated by Open.
 *
 * Threads: after Open (main thread), Send and ReceiveLatest belong to one
 * thread at a time (the haptic loop's); the counters may be read from any.
 * POSIX sockets; on Windows, Winsock 2.
 *
 * @sa vtkHapticCoupling vtkHapticLoop
 */

#ifndef vtkHapticCouplingTransport_h
#define vtkHapticCouplingTransport_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals
#include <string> // For GetPeerAddress

class vtkImageData;
class vtkMatrix4x4;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticCouplingTransport : public vtkObject
{
public:
  static vtkHapticCouplingTransport* New();
  vtkTypeMacro(vtkHapticCouplingTransport, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The packet layout's version; a packet of another version is refused.
  static constexpr int ProtocolVersion = 2;
  /// Size of an encoded packet (bytes).
  static constexpr int PacketSize = 104;

#ifndef __VTK_WRAP__
  /// What one packet carries (positions RAS mm, velocities mm/s, energies mJ = N mm).
  struct State
  {
    /// The sender's nonce, new at each Open: a restarted peer is a new session.
    unsigned int Session = 0;
    /// Counts the sender's packets from 1.
    unsigned long long Sequence = 0;
    /// The sender's clock (s) when it sent the packet.
    double Time = 0.0;
    double Position[3] = { 0.0, 0.0, 0.0 };
    double Velocity[3] = { 0.0, 0.0, 0.0 };
    /// Energy the sender has shipped to its peer since its session began (never decreases).
    double EnergySent = 0.0;
    /// The sender's stored energy (informative).
    double Tank = 0.0;
    /// PresentFlag: the sender's device has a pose.
    unsigned int Flags = 0;
    /// The frame Position and Velocity are in (see FrameFingerprint).
    unsigned long long Frame = 0;
  };
  static constexpr unsigned int PresentFlag = 1u;

  /// Encode into PacketSize bytes (sequence, session and checksum as given / computed).
  static void EncodePacket(const State& state, unsigned char packet[PacketSize]);

  /// Decode and check a datagram; false (state untouched) if it is garbled.
  static bool DecodePacket(const unsigned char* packet, int size, State& state);

  /**
   * Send the local state (its Session and Sequence are filled in here), at
   * time now (s, the caller's clock: the injected delay counts on it).
   * False if it was lost by injection or the socket had no room (counted).
   */
  bool Send(State& state, double now);

  /**
   * Write the delayed packets that are due at now, drain the socket and
   * return whether a new valid packet arrived; latest is then the newest.
   */
  bool ReceiveLatest(double now, State& latest);

  /**
   * Write any bytes to the peer at once, bypassing encoding and injection:
   * for probing a peer's defences (tests, diagnostics). False if not written.
   */
  bool SendRawDatagram(const unsigned char* bytes, int size);
#endif

  /**
   * Bind a UDP socket on host:localPort (0: any free port, see
   * GetLocalPort) and address the peer at remoteHost:remotePort (numeric
   * IPv4). False, with an error saying why, otherwise. Allocates the
   * injection queue; starts a new session.
   *
   * remotePort 0 listens instead: the peer is whoever sends the first valid
   * packet (from remoteHost only, unless it is 0.0.0.0), and nothing is sent
   * until then. The side that waits (the trainee's) need not know the
   * address of the side that joins, which may be behind a NAT: replies go
   * where its packets come from. Packets from another address are foreign
   * while the peer is alive; once it has been silent for SessionTimeout, a
   * new address may take its place (the instructor's side restarted).
   */
  bool Open(const char* localHost, int localPort, const char* remoteHost, int remotePort);
  void Close();
  bool IsOpen() const;

  /// The bound port (after Open), 0 when closed.
  int GetLocalPort() const;

  /// This side's session nonce (after Open).
  unsigned int GetSession() const;

  /// Whether Open was asked to listen (remote port 0) rather than to address a known peer.
  bool IsListening() const;

  /**
   * The peer's address as "host:port": the one given to Open, or, when
   * listening, the one the accepted packets come from ("" until one came).
   * Any thread may ask while the loop runs.
   */
  std::string GetPeerAddress() const;

  ///@{
  /**
   * Set/get the frame this side's positions are in, sent in every packet;
   * packets in another frame are refused. 0 (default): the device's own
   * millimetres; otherwise ComputeFrameFingerprint of the shared scan. Set
   * while the haptic thread does not send.
   */
  vtkSetMacro(FrameFingerprint, unsigned long long);
  vtkGetMacro(FrameFingerprint, unsigned long long);
  ///@}

  /**
   * A fingerprint of a scan's RAS frame and content: its dimensions, its
   * IJK-to-RAS matrix (spacing, origin, axes), its scalar type and a 64-bit
   * FNV-1a checksum of its samples. Two sessions that loaded the same scan
   * get the same value on any machine; a scan that differs in any of these
   * (another patient, a resampled or cropped copy) almost surely another.
   * Never 0 for an image with samples (0 means "no scan"); 0 for nullptr or
   * an image without scalars.
   */
  static unsigned long long ComputeFrameFingerprint(vtkImageData* anatomy, vtkMatrix4x4* ijkToRAS);

  ///@{
  /**
   * Valid packets refused because their frame differs from this side's,
   * and the frame the last of them carried (0: none so far).
   */
  unsigned long long GetNumberOfFrameMismatches() const;
  unsigned long long GetLastRefusedFrame() const;
  ///@}

  ///@{
  /**
   * Set/get the time (s) without a packet after which a packet from another
   * session is taken as the peer's restart. Default is 0.5.
   */
  vtkSetClampMacro(SessionTimeout, double, 0.0, 3600.0);
  vtkGetMacro(SessionTimeout, double);
  ///@}

  ///@{
  /**
   * Fault injection on this side's outgoing packets: a delay (s, 0 to 1),
   * a loss rate (0 to 1) and the generator's seed. Defaults: none, seed 1.
   * Set while the haptic thread does not send.
   */
  vtkSetClampMacro(InjectedDelay, double, 0.0, 1.0);
  vtkGetMacro(InjectedDelay, double);
  vtkSetClampMacro(InjectedLossRate, double, 0.0, 1.0);
  vtkGetMacro(InjectedLossRate, double);
  void SetInjectionSeed(unsigned long long seed);
  vtkGetMacro(InjectionSeed, unsigned long long);
  ///@}

  ///@{
  /**
   * Counts since Open: packets written, lost by injection, not written (no
   * room in the socket or the injection queue), accepted, and dropped as
   * garbled, stale, from another session, or from another host.
   */
  unsigned long long GetNumberOfPacketsSent() const;
  unsigned long long GetNumberOfPacketsLostByInjection() const;
  unsigned long long GetNumberOfSendFailures() const;
  unsigned long long GetNumberOfPacketsAccepted() const;
  unsigned long long GetNumberOfGarbledPackets() const;
  unsigned long long GetNumberOfStalePackets() const;
  unsigned long long GetNumberOfForeignSessionPackets() const;
  unsigned long long GetNumberOfForeignHostPackets() const;
  ///@}

protected:
  vtkHapticCouplingTransport();
  ~vtkHapticCouplingTransport() override;

  double SessionTimeout = 0.5;
  unsigned long long FrameFingerprint = 0;
  double InjectedDelay = 0.0;
  double InjectedLossRate = 0.0;
  unsigned long long InjectionSeed = 1;

  struct Internals;
  std::unique_ptr<Internals> Internal;

private:
  vtkHapticCouplingTransport(const vtkHapticCouplingTransport&) = delete;
  void operator=(const vtkHapticCouplingTransport&) = delete;
};

#endif
