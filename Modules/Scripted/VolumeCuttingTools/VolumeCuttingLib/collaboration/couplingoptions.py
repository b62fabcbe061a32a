"""Command-line options for forces forwarded: which side waits, which side joins, and where.

The trainee's side waits (``--couple-listen PORT``), the instructor's side
joins it (``--couple-to HOST:PORT``). The link is UDP, one datagram a tick
each way; the side that waits answers wherever the joining side's packets
come from, so only the trainee's port needs to be reachable. What each side
feels is the same spring between the two tools, seen from each end: the
instructor's device is pulled toward the trainee's tool (they feel where it
is and how it resists), the trainee's device toward the instructor's (they
feel the instructor guide them).
"""

from __future__ import annotations

import ipaddress
import socket
import time
from dataclasses import dataclass

from .forcecoupling import LOOPBACK, CouplingSettings, describe_mismatch

TRAINEE = "trainee"
INSTRUCTOR = "instructor"
#: How long the instructor's side waits for the trainee's first packet before it gives up (s).
DEFAULT_ANSWER_TIMEOUT_S = 10.0

LISTEN_HELP = ("trainee's side: wait on UDP PORT (0: any free port, printed) for an instructor's device to join with "
               "--couple-to. Your device is then pulled toward the instructor's tool (a spring between the two, at most "
               "your device's force): the instructor guides your hand; they feel where your tool is and how it resists.")
TO_HELP = ("instructor's side: couple your device to the trainee's session waiting at HOST:PORT (--couple-listen PORT). "
           "Your device is pulled toward the trainee's tool: you feel where it is and how it resists, and pulling your "
           "device guides the trainee's, who feels your pull.")


@dataclass(frozen=True)
class CouplingOptions:
    """One side's place in the coupling, from the command line."""

    role: str                    # TRAINEE (waits) or INSTRUCTOR (joins)
    port: int                    # the trainee's: the port it waits on; the instructor's: the trainee's port
    peer_host: str = LOOPBACK    # the instructor's: the trainee's numeric address
    host: str = LOOPBACK         # the address this side's socket is bound to
    stiffness: float = 0.5       # N per scene mm
    answer_timeout_s: float = DEFAULT_ANSWER_TIMEOUT_S

    @property
    def joins(self) -> bool:
        return self.role == INSTRUCTOR

    def settings(self, frame_fingerprint: int = 0) -> CouplingSettings:
        """The coupling's settings for this side (the trainee's listens: peer port 0), in the frame of the scan
        whose fingerprint is given (0: the devices' own millimetres)."""
        if self.joins:
            return CouplingSettings(local_port=0, peer_port=self.port, host=self.host, peer_host=self.peer_host,
                                    stiffness=self.stiffness, frame_fingerprint=frame_fingerprint)
        return CouplingSettings(local_port=self.port, peer_port=0, host=self.host, peer_host="0.0.0.0",
                                stiffness=self.stiffness, frame_fingerprint=frame_fingerprint)

    def describe(self) -> str:
        if self.joins:
            return f"instructor's side, joining the trainee at {self.peer_host}:{self.port}"
        return f"trainee's side, waiting for the instructor on {self.host}:{self.port}"


def add_arguments(parser) -> None:
    """The coupling's options, in a group of their own."""
    group = parser.add_argument_group(
        "forces forwarded", "couple this haptic device to another's over UDP: the instructor guides the trainee")
    sides = group.add_mutually_exclusive_group()
    sides.add_argument("--couple-listen", type=int, default=None, metavar="PORT", help=LISTEN_HELP)
    sides.add_argument("--couple-to", default=None, metavar="HOST:PORT", help=TO_HELP)
    group.add_argument("--couple-host", default=None, metavar="HOST",
                       help="address this side's UDP socket is bound to (default 127.0.0.1, this machine only, when "
                            "waiting or joining on this machine; 0.0.0.0 when joining another machine). Give 0.0.0.0 "
                            "or this machine's address with --couple-listen for an instructor on another machine")
    group.add_argument("--couple-stiffness", type=float, default=0.5, metavar="N_PER_MM",
                       help="stiffness of the spring between the two tools (default 0.5 N/mm; the device's own limit "
                            "caps it)")
    group.add_argument("--couple-wait", type=float, default=DEFAULT_ANSWER_TIMEOUT_S, metavar="SECONDS",
                       help="with --couple-to: give up when the trainee's side has not answered within this time "
                            f"(default {DEFAULT_ANSWER_TIMEOUT_S:g} s)")


def _numeric_host(text: str, what: str) -> str:
    """A numeric IPv4 address for ``text`` (a name is resolved); ValueError saying what went wrong."""
    try:
        return str(ipaddress.IPv4Address(text))
    except ValueError:
        pass
    try:
        infos = socket.getaddrinfo(text, None, socket.AF_INET, socket.SOCK_DGRAM)
    except (socket.gaierror, UnicodeError) as error:
        raise ValueError(f"{what}: the host {text!r} could not be found ({error}); give a name this machine resolves or "
                         "a numeric address such as 192.168.1.20") from None
    return infos[0][4][0]


def parse_peer(text: str, what: str = "--couple-to") -> tuple[str, int]:
    """``HOST:PORT`` as (numeric IPv4 address, port); ValueError naming ``what`` (the option or field) and the fault."""
    host, separator, port_text = str(text).strip().rpartition(":")
    if not separator or not host or not port_text.isdigit() or not 1 <= int(port_text) <= 65535:
        raise ValueError(f"{what} {text!r}: expected HOST:PORT with a port from 1 to 65535, "
                         "such as 192.168.1.20:47000 (the port the trainee's side shows)")
    return _numeric_host(host, f"{what} {text!r}"), int(port_text)


def joining_host(peer_host: str) -> str:
    """Where the joining side binds by default: this machine only for a peer on it, else every interface."""
    return LOOPBACK if ipaddress.IPv4Address(peer_host).is_loopback else "0.0.0.0"


def options_from_arguments(args) -> CouplingOptions | None:
    """The coupling asked for on the command line, None if none; ValueError with a message for the user."""
    listen, to = getattr(args, "couple_listen", None), getattr(args, "couple_to", None)
    if listen is None and to is None:
        return None
    stiffness, wait = float(args.couple_stiffness), float(args.couple_wait)
    if not 0.0 < stiffness <= 100.0:
        raise ValueError(f"--couple-stiffness {args.couple_stiffness}: give a stiffness above 0 and at most 100 N/mm")
    if not 0.0 < wait <= 3600.0:
        raise ValueError(f"--couple-wait {args.couple_wait}: give a time above 0 and at most 3600 s")
    if listen is not None:
        if not 0 <= listen <= 65535:
            raise ValueError(f"--couple-listen {listen}: give a port from 0 (any free port) to 65535")
        host = _numeric_host(args.couple_host or LOOPBACK, "--couple-host")
        return CouplingOptions(TRAINEE, listen, host=host, stiffness=stiffness, answer_timeout_s=wait)
    peer_host, port = parse_peer(to)
    loopback = ipaddress.IPv4Address(peer_host).is_loopback
    host = _numeric_host(args.couple_host or joining_host(peer_host), "--couple-host")
    if loopback != ipaddress.IPv4Address(host).is_loopback and host != "0.0.0.0":
        raise ValueError(f"--couple-host {host} cannot reach the trainee at {peer_host}: leave --couple-host out")
    return CouplingOptions(INSTRUCTOR, port, peer_host=peer_host, host=host, stiffness=stiffness, answer_timeout_s=wait)


#: A peer silent this long (s) is reported gone; the coupling has faded its pull out by 0.15 s.
PEER_GONE_S = 0.5


class PeerWatch:
    """Tells when the peer joins, goes and comes back, from one side's coupling status (any thread may look)."""

    def __init__(self, options: CouplingOptions, coupling):
        self.options = options
        self.coupling = coupling  # forcecoupling.ForceCoupling
        self.events: list[dict] = []
        self.joined = False
        self.present = False
        self.mismatch = None
        self._started = time.perf_counter()

    def elapsed(self) -> float:
        return time.perf_counter() - self._started

    def look(self, say=print) -> dict:
        """The coupling's status; an event told through ``say`` when the peer came, went or came back."""
        status = self.coupling.status()
        peer = "the instructor" if self.options.role == TRAINEE else "the trainee"
        age = status["peer_age_s"]
        alive = status["packets_accepted"] > 0 and 0.0 <= age < PEER_GONE_S
        if alive and not self.present:
            self._event(f"{peer} {'is back' if self.joined else 'joined'} from {status['peer']}", say)
            self.joined = self.present = True
        elif not alive and self.present:
            self._event(f"{peer} is gone (nothing for {PEER_GONE_S:g} s): its pull faded out; this side goes on and "
                        "takes it back when it returns", say)
            self.present = False
        if self.mismatch is None:
            self.mismatch = describe_mismatch(status, peer)
            if self.mismatch:
                self._event(self.mismatch, say)
        return status

    def never_answered(self) -> str | None:
        """On the joining side, once the wait is over with no answer: what to tell the user; None otherwise."""
        if not self.options.joins or self.joined or self.elapsed() <= self.options.answer_timeout_s:
            return None
        port = self.options.port
        return (f"no trainee answered at {self.options.peer_host}:{port} within {self.options.answer_timeout_s:g} s: "
                f"start the trainee's side first (--couple-listen {port}), check the address, and that UDP port {port} "
                "is open between the machines (a firewall refuses it silently)")

    def refused(self) -> str | None:
        """On the joining side, once the trainee's side was refused for its scan: what to tell the user."""
        return self.mismatch if self.options.joins and not self.joined else None

    def _event(self, what: str, say) -> None:
        self.events.append({"t_s": round(self.elapsed(), 3), "event": what})
        say(what)
