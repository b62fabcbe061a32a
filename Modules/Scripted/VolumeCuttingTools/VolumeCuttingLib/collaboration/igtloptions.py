"""Where the OpenIGTLink bridge listens and how fast it streams, and the command-line options that say so.

Apart from ``igtlbridge`` (which needs pyigtl) so that the main job and the
web application parse ``--openigtlink`` without importing pyigtl unless the
bridge is asked for: desktop Slicer brings its own OpenIGTLink and no pyigtl.
"""

from __future__ import annotations

from dataclasses import dataclass

DEFAULT_HOST = "127.0.0.1"


@dataclass
class BridgeOptions:
    """Where the bridge listens and how fast it streams (see ``igtlbridge``)."""

    port: int = 18944  # OpenIGTLink's registered port; 0 picks a free one
    host: str = DEFAULT_HOST
    pose_rate_hz: float = 60.0
    monitor_rate_hz: float = 20.0
    # Each image update recomputes the changed bricks' fractions on the bridge's thread: a few a second.
    image_rate_hz: float = 5.0
    max_clients: int = 8
    stall_timeout_s: float = 2.0
    max_backlog_bytes: int = 64 * 1024 * 1024
    # The kernel's send buffer per client: what a client that stops reading holds before the bridge sees it stall
    # (and what stale poses a slow one still gets); 0 leaves the system's (megabytes, on loopback).
    send_buffer_bytes: int = 256 * 1024
    stroke_idle_s: float = 0.25

    def __post_init__(self):
        if not 0 <= int(self.port) <= 65535:
            raise ValueError(f"OpenIGTLink port {self.port}: give 0 to 65535")
        for name in ("pose_rate_hz", "monitor_rate_hz", "image_rate_hz"):
            if not 1.0 <= getattr(self, name) <= 1000.0:
                raise ValueError(f"OpenIGTLink {name.replace('_', ' ')} {getattr(self, name)}: give 1 to 1000 per second")


def add_arguments(parser) -> None:
    """``--openigtlink PORT`` (off by default) and ``--openigtlink-host HOST`` (127.0.0.1 unless given)."""
    group = parser.add_argument_group("OpenIGTLink", "mirror the session in desktop Slicer (SlicerOpenIGTLink) and take poses from it")
    group.add_argument("--openigtlink", type=int, default=None, metavar="PORT",
                       help="serve the session over OpenIGTLink on this port (18944 is the usual one; 0 picks a free one)")
    group.add_argument("--openigtlink-host", default=DEFAULT_HOST, metavar="HOST",
                       help="address the OpenIGTLink server listens on (default 127.0.0.1: this machine only; "
                            "0.0.0.0 lets other machines connect)")


def options_from_arguments(args) -> BridgeOptions | None:
    """The bridge's options from parsed arguments, or None without ``--openigtlink``; ValueError for a bad port."""
    if args.openigtlink is None:
        if args.openigtlink_host != DEFAULT_HOST:
            raise ValueError("--openigtlink-host goes with --openigtlink PORT")
        return None
    return BridgeOptions(port=args.openigtlink, host=args.openigtlink_host)
