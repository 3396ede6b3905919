"""`gauss6 device list`: the HID devices hidapi sees, with the gauss6 profile of each.

list_devices() returns dicts (path, vendor_id, product_id, serial, manufacturer, product,
interface_number, profile: the profile name or None); format_devices() prints them.
"""
from __future__ import annotations


def list_devices() -> list[dict]:
    """Every HID interface on this machine (through hidapi); empty when there is none."""
    from ._gauss6 import device as _device

    return list(_device.list_hid_devices())


def format_devices(devices: list[dict]) -> str:
    """One line per device; supported devices (with a profile) first."""
    if not devices:
        return "no HID devices found"
    ordered = sorted(devices, key=lambda d: (d["profile"] is None, d["path"]))
    lines = []
    for d in ordered:
        ident = f"{d['vendor_id']:04x}:{d['product_id']:04x}"
        name = d["profile"] or f"{d['manufacturer']} {d['product']}".strip() or "unknown"
        support = "supported" if d["profile"] else "no profile"
        serial = f" serial {d['serial']}" if d["serial"] else ""
        lines.append(f"{ident}  {name}  ({support}){serial}  {d['path']}")
    return "\n".join(lines)


def profiles() -> list[dict]:
    """The known device profiles (vendor_id, product_id, name, layout, num_buttons, ...)."""
    from ._gauss6 import device as _device

    return list(_device.hid_profiles())
