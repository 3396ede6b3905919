"""Devices from Python: `gauss6 device list`, the HID profiles, the simulated device in lockstep."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

from gauss6 import device
from gauss6._gauss6 import device as _device


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gauss6.cli", *args], capture_output=True, text=True)


def test_device_list_command():
    devices = device.list_devices()
    r = run_cli("device", "list")
    assert r.returncode == 0, r.stderr
    if not devices:
        # This machine has no HID devices: the command says so.
        assert r.stdout.strip() == "no HID devices found"
    else:
        assert len(r.stdout.strip().splitlines()) == len(devices)
    r = run_cli("device", "list", "--json")
    assert r.returncode == 0 and json.loads(r.stdout) == devices


def test_format_devices_marks_supported_ones():
    entries = [
        {"path": "/dev/hidraw1", "vendor_id": 0x046d, "product_id": 0xc077, "serial": "", "manufacturer": "Logitech",
         "product": "USB Optical Mouse", "interface_number": 0, "profile": None},
        {"path": "/dev/hidraw3", "vendor_id": 0x256f, "product_id": 0xc635, "serial": "X1",
         "manufacturer": "3Dconnexion", "product": "SpaceMouse Compact", "interface_number": 0,
         "profile": "3Dconnexion SpaceMouse Compact"},
    ]
    lines = device.format_devices(entries).splitlines()
    assert lines[0].startswith("256f:c635  3Dconnexion SpaceMouse Compact  (supported) serial X1")
    assert "(no profile)" in lines[1]
    assert device.format_devices([]) == "no HID devices found"


def test_profiles_cover_the_spacemouse_family():
    ids = {(p["vendor_id"], p["product_id"]) for p in device.profiles()}
    for pid in (0xc626, 0xc62b):
        assert (0x046d, pid) in ids
    for pid in (0xc62e, 0xc62f, 0xc633, 0xc635):
        assert (0x256f, pid) in ids
    assert all(not p["renders_force"] for p in device.profiles())


def test_simulated_device_from_python_is_deterministic_and_feels_the_force():
    script = json.dumps({"keys": [{"t": 0, "p": [0, 0, 0]}], "end_time": 3})

    def run(force):
        d = _device.SimulatedDevice(script)
        out = []
        for i in range(3001):
            p, q, gripped, status = d.read(i * 1e-3)
            out.append(p)
            d.write(i * 1e-3, force)
        return np.array(out)

    F = np.array([1.0, 0, 0, 0, 0, 0])
    a, b = run(F), run(F)
    np.testing.assert_array_equal(a, b)  # bit-identical
    # Steady state against the default grip stiffness of 500 N/m: F/k = 2 mm (transient < exp(-90)).
    np.testing.assert_allclose(a[-1], [1.0 / 500, 0, 0], atol=1e-12)
