"""Input devices a drill can be driven with: the mouse, and known USB devices.

Standard library only (ctypes): the device listing works wherever hidapi and
libusb are installed (Debian: ``libhidapi-hidraw0``, ``libusb-1.0-0``) and
quietly finds nothing where they are missing or where the machine has no USB
(as on this project's CI machines). HID devices (SpaceMouse, foot switches)
are enumerated through hidapi's hidraw backend; devices that need raw USB
(the Novint Falcon's FTDI chip) through libusb.

The known devices and their identifiers are those of
``/work/shared/notes/devices.md`` (public sources: libnifalcon, spacenavd,
PySpaceMouse).
"""

from __future__ import annotations

import ctypes
import logging
from dataclasses import dataclass

#: Transports of known devices.
HID = "hid"
USB = "usb"

#: Kinds of input, what the product does with each.
MOUSE = "mouse"
HAPTIC = "haptic"
SIX_DOF = "6dof"
FOOT_SWITCH = "footswitch"


@dataclass(frozen=True)
class KnownDevice:
    vendor_id: int
    product_id: int
    name: str
    kind: str
    transport: str


KNOWN_DEVICES: tuple[KnownDevice, ...] = (
    KnownDevice(0x0403, 0xCB48, "Novint Falcon", HAPTIC, USB),
    KnownDevice(0x256F, 0xC62E, "3Dconnexion SpaceMouse Wireless (cable)", SIX_DOF, HID),
    KnownDevice(0x256F, 0xC632, "3Dconnexion SpaceMouse Pro Wireless (cable)", SIX_DOF, HID),
    KnownDevice(0x256F, 0xC633, "3Dconnexion SpaceMouse Enterprise", SIX_DOF, HID),
    KnownDevice(0x256F, 0xC638, "3Dconnexion SpaceMouse Pro Wireless (receiver)", SIX_DOF, HID),
    KnownDevice(0x256F, 0xC652, "3Dconnexion Universal Receiver", SIX_DOF, HID),
    KnownDevice(0x05F3, 0x00FF, "VEC Infinity IN-USB-2 foot switch", FOOT_SWITCH, HID),
    KnownDevice(0x0C45, 0x7403, "PCsensor foot switch", FOOT_SWITCH, HID),
    KnownDevice(0x0C45, 0x7404, "PCsensor foot switch", FOOT_SWITCH, HID),
    KnownDevice(0x413D, 0x2107, "iKKEGOL foot switch", FOOT_SWITCH, HID),
    KnownDevice(0x1A86, 0xE026, "iKKEGOL foot switch", FOOT_SWITCH, HID),
)

#: Identifier of the virtual device that is always there.
MOUSE_DEVICE_ID = "mouse"

HIDAPI_LIBRARY = "libhidapi-hidraw.so.0"
LIBUSB_LIBRARY = "libusb-1.0.so.0"


@dataclass(frozen=True)
class InputDevice:
    """One device the user can choose to drive the tool with.

    ``device_id`` is stable while the device stays plugged in: the hidraw path,
    ``usb:<bus>:<address>`` for libusb devices, ``mouse`` for the mouse.
    """

    device_id: str
    name: str
    kind: str
    backend: str
    vendor_id: int = 0
    product_id: int = 0
    serial_number: str = ""

    @property
    def label(self) -> str:
        """What a device list shows."""
        if self.backend == "virtual":
            return self.name
        suffix = f", serial {self.serial_number}" if self.serial_number else ""
        return f"{self.name} ({self.vendor_id:04x}:{self.product_id:04x}{suffix})"


MOUSE_DEVICE = InputDevice(MOUSE_DEVICE_ID, "Mouse (virtual drill in the 3D view)", MOUSE, "virtual")


def known_device(vendor_id: int, product_id: int, transport: str) -> KnownDevice | None:
    for device in KNOWN_DEVICES:
        if (device.vendor_id, device.product_id, device.transport) == (vendor_id, product_id, transport):
            return device
    return None


def list_devices() -> list[InputDevice]:
    """The mouse, then the known HID and USB devices plugged in.

    Never raises: a missing library, a failed enumeration or a machine without
    USB gives the mouse alone (the reason is logged at debug level).
    """
    devices = [MOUSE_DEVICE]
    for backend in (list_hid_devices, list_usb_devices):
        try:
            devices.extend(backend())
        except (OSError, AttributeError, ValueError) as error:
            # A library of another ABI or without a symbol: no devices from it.
            logging.warning("Listing input devices with %s failed: %s", backend.__name__, error)
    return devices


def _load(library_name: str):
    try:
        return ctypes.CDLL(library_name)
    except OSError as error:
        logging.debug("%s is not available: %s", library_name, error)
        return None


class _HidDeviceInfo(ctypes.Structure):
    """The leading fields of hidapi's ``struct hid_device_info`` (0.9 to 0.14)."""


_HidDeviceInfo._fields_ = [
    ("path", ctypes.c_char_p),
    ("vendor_id", ctypes.c_ushort),
    ("product_id", ctypes.c_ushort),
    ("serial_number", ctypes.c_wchar_p),
    ("release_number", ctypes.c_ushort),
    ("manufacturer_string", ctypes.c_wchar_p),
    ("product_string", ctypes.c_wchar_p),
    ("usage_page", ctypes.c_ushort),
    ("usage", ctypes.c_ushort),
    ("interface_number", ctypes.c_int),
    ("next", ctypes.POINTER(_HidDeviceInfo)),
]


def list_hid_devices(library_name: str = HIDAPI_LIBRARY) -> list[InputDevice]:
    """Known HID devices, through hidapi (one entry per hidraw node)."""
    hidapi = _load(library_name)
    if hidapi is None:
        return []
    hidapi.hid_init.restype = ctypes.c_int
    hidapi.hid_enumerate.restype = ctypes.POINTER(_HidDeviceInfo)
    hidapi.hid_enumerate.argtypes = [ctypes.c_ushort, ctypes.c_ushort]
    hidapi.hid_free_enumeration.argtypes = [ctypes.POINTER(_HidDeviceInfo)]
    if hidapi.hid_init() != 0:
        logging.debug("hid_init failed")
        return []
    devices = []
    first = hidapi.hid_enumerate(0, 0)
    try:
        entry = first
        while entry:
            info = entry.contents
            known = known_device(info.vendor_id, info.product_id, HID)
            if known is not None:
                devices.append(
                    InputDevice(
                        device_id=(info.path or b"").decode(errors="replace"),
                        name=info.product_string or known.name,
                        kind=known.kind,
                        backend="hidapi",
                        vendor_id=info.vendor_id,
                        product_id=info.product_id,
                        serial_number=info.serial_number or "",
                    )
                )
            entry = info.next
    finally:
        if first:
            hidapi.hid_free_enumeration(first)
    return devices


class _UsbDeviceDescriptor(ctypes.Structure):
    """libusb's ``struct libusb_device_descriptor`` (the USB device descriptor)."""

    _fields_ = [
        ("bLength", ctypes.c_uint8),
        ("bDescriptorType", ctypes.c_uint8),
        ("bcdUSB", ctypes.c_uint16),
        ("bDeviceClass", ctypes.c_uint8),
        ("bDeviceSubClass", ctypes.c_uint8),
        ("bDeviceProtocol", ctypes.c_uint8),
        ("bMaxPacketSize0", ctypes.c_uint8),
        ("idVendor", ctypes.c_uint16),
        ("idProduct", ctypes.c_uint16),
        ("bcdDevice", ctypes.c_uint16),
        ("iManufacturer", ctypes.c_uint8),
        ("iProduct", ctypes.c_uint8),
        ("iSerialNumber", ctypes.c_uint8),
        ("bNumConfigurations", ctypes.c_uint8),
    ]


def list_usb_devices(library_name: str = LIBUSB_LIBRARY) -> list[InputDevice]:
    """Known raw-USB devices (the Falcon), through libusb. Descriptors only: nothing is opened."""
    libusb = _load(library_name)
    if libusb is None:
        return []
    libusb.libusb_init.argtypes = [ctypes.POINTER(ctypes.c_void_p)]
    libusb.libusb_exit.argtypes = [ctypes.c_void_p]
    libusb.libusb_get_device_list.restype = ctypes.c_ssize_t
    libusb.libusb_get_device_list.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.POINTER(ctypes.c_void_p))]
    libusb.libusb_free_device_list.argtypes = [ctypes.POINTER(ctypes.c_void_p), ctypes.c_int]
    libusb.libusb_get_device_descriptor.argtypes = [ctypes.c_void_p, ctypes.POINTER(_UsbDeviceDescriptor)]
    libusb.libusb_get_bus_number.restype = ctypes.c_uint8
    libusb.libusb_get_bus_number.argtypes = [ctypes.c_void_p]
    libusb.libusb_get_device_address.restype = ctypes.c_uint8
    libusb.libusb_get_device_address.argtypes = [ctypes.c_void_p]

    context = ctypes.c_void_p()
    if libusb.libusb_init(ctypes.byref(context)) != 0:
        logging.debug("libusb_init failed")
        return []
    devices = []
    try:
        device_list = ctypes.POINTER(ctypes.c_void_p)()
        count = libusb.libusb_get_device_list(context, ctypes.byref(device_list))
        if count < 0:
            logging.debug("libusb_get_device_list failed: %d", count)
            return []
        try:
            for index in range(count):
                device = device_list[index]
                descriptor = _UsbDeviceDescriptor()
                if libusb.libusb_get_device_descriptor(device, ctypes.byref(descriptor)) != 0:
                    continue
                known = known_device(descriptor.idVendor, descriptor.idProduct, USB)
                if known is None:
                    continue
                bus = libusb.libusb_get_bus_number(device)
                address = libusb.libusb_get_device_address(device)
                devices.append(
                    InputDevice(
                        device_id=f"usb:{bus}:{address}",
                        name=known.name,
                        kind=known.kind,
                        backend="libusb",
                        vendor_id=descriptor.idVendor,
                        product_id=descriptor.idProduct,
                    )
                )
        finally:
            libusb.libusb_free_device_list(device_list, 1)
    finally:
        libusb.libusb_exit(context)
    return devices
