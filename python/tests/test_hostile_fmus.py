"""FMU archives contained: hostile FMUs made here from this repository's
DC-motor FMU, each refused by the pre-flight check (exit 2, one line naming the entry or the
identifier) before anything is extracted or loaded:

* the library entry `binaries/linux64/dc_motor.so` replaced by a symbolic link to a host library
  (before: passed `--check`, and the run dlopened the host file);
* a `modelIdentifier` that is a path (`../../../tmp/evil`, `/usr/lib/…/libm`);
* the library with the setuid bit;
* more entries than an FMU may hold;
* a library that exports no FMI function (before: it loaded, and the first call panicked the
  plant, exit 101, "run with RUST_BACKTRACE");
* a library for another architecture (before: "cannot open shared object file: No such file or
  directory" about a file that exists).
"""

import os
import re
import shutil
import stat
import subprocess
import zipfile

import pytest

from test_diagnosis_scipy import launcher
from test_fmu_testfmus import fmu_dir  # noqa: F401 (fixture)

LIBRARY = "binaries/linux64/dc_motor.so"


def rebuild(src, dst, edit):
    """Copies the archive entry by entry; `edit(info, data)` returns the entries to write
    instead of each (a list of (ZipInfo, bytes))."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            for new, data in edit(info, zin.read(info)):
                zout.writestr(new, data)


def scenario(tmp_path, fmu):
    s = tmp_path / "s.toml"
    s.write_text(f"""name = "hostile"
dt = 0.01
duration = 0.1
[plant]
A = [[-4.0, -0.2, 0.0], [5.0, -2.5, 0.0], [0.0, 1.0, 0.0]]
B = [[2.0], [0.0], [0.0]]
C = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
E = [[0.0], [-50.0], [0.0]]
x0 = [0.0, 0.0, 0.0]
[plant.fmu]
path = "{fmu}"
inputs = ["u1"]
disturbances = ["w1"]
outputs = ["y1", "y2"]
states = ["x1", "x2", "x3"]
[[input]]
kind = "constant"
value = 1.0
[[disturbance]]
kind = "constant"
value = 0.0
[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-5.0, -6.0, -7.0]
""")
    return s


def refused(tmp_path, fmu, says):
    p = subprocess.run([launcher(), "run", str(scenario(tmp_path, fmu)), "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and says in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []
    print(p.stderr.strip())


def test_the_untouched_fmu_runs(fmu_dir, tmp_path):  # noqa: F811
    """The control case: the archive these tests edit passes and runs."""
    p = subprocess.run([launcher(), "run", str(scenario(tmp_path, os.path.join(fmu_dir, "dc_motor_fmi2.fmu"))), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr


def test_a_library_that_is_a_symbolic_link_is_refused(fmu_dir, tmp_path):  # noqa: F811
    bad = tmp_path / "link.fmu"

    def edit(info, data):
        if info.filename != LIBRARY:
            return [(info, data)]
        link = zipfile.ZipInfo(LIBRARY)
        link.create_system = 3
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        return [(link, b"/lib/x86_64-linux-gnu/libm.so.6")]

    rebuild(os.path.join(fmu_dir, "dc_motor_fmi2.fmu"), bad, edit)
    refused(tmp_path, bad, f"entry '{LIBRARY}' is a symbolic link")


@pytest.mark.parametrize("identifier", ["../../../tmp/evil", "/usr/lib/x86_64-linux-gnu/libm"])
def test_a_model_identifier_that_is_a_path_is_refused(fmu_dir, tmp_path, identifier):  # noqa: F811
    bad = tmp_path / "path.fmu"

    def edit(info, data):
        if info.filename == "modelDescription.xml":
            return [(info, re.sub(rb'modelIdentifier="[^"]*"', f'modelIdentifier="{identifier}"'.encode(), data))]
        return [(info, data)]

    rebuild(os.path.join(fmu_dir, "dc_motor_fmi2.fmu"), bad, edit)
    refused(tmp_path, bad, "is not a plain file name")


def test_a_setuid_library_is_refused(fmu_dir, tmp_path):  # noqa: F811
    bad = tmp_path / "setuid.fmu"

    def edit(info, data):
        if info.filename == LIBRARY:
            info.create_system = 3
            info.external_attr = (stat.S_IFREG | stat.S_ISUID | 0o755) << 16
        return [(info, data)]

    rebuild(os.path.join(fmu_dir, "dc_motor_fmi2.fmu"), bad, edit)
    refused(tmp_path, bad, "setuid or setgid")


def test_an_archive_of_too_many_entries_is_refused(fmu_dir, tmp_path):  # noqa: F811
    bad = tmp_path / "many.fmu"
    shutil.copy(os.path.join(fmu_dir, "dc_motor_fmi2.fmu"), bad)
    with zipfile.ZipFile(bad, "a") as z:
        for i in range(10_001):
            z.writestr(f"resources/empty{i}", b"")
    refused(tmp_path, bad, "more than the 10000")


def empty_library(tmp_path):
    """A real x86-64 shared library with one function and no FMI symbol, built here."""
    src = tmp_path / "empty.c"
    src.write_text("int nothing(void) { return 0; }\n")
    out = tmp_path / "empty.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(out), str(src)], check=True)
    return out.read_bytes()


def with_library(fmu_dir, tmp_path, name, library):
    bad = tmp_path / name
    rebuild(os.path.join(fmu_dir, "dc_motor_fmi2.fmu"), bad, lambda info, data: [(info, library if info.filename == LIBRARY else data)])
    return bad


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler to build the library")
def test_a_library_without_the_fmi_functions_is_refused_before_it_loads(fmu_dir, tmp_path):  # noqa: F811
    bad = with_library(fmu_dir, tmp_path, "nosym.fmu", empty_library(tmp_path))
    refused(tmp_path, bad, f"{LIBRARY} does not export fmi2Instantiate, fmi2FreeInstance, fmi2SetupExperiment and 7 more: not an FMI 2.0 co-simulation library")


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler to build the library")
def test_a_library_for_another_architecture_is_named_as_such(fmu_dir, tmp_path):  # noqa: F811
    arm = bytearray(empty_library(tmp_path))
    assert arm[:4] == b"\x7fELF" and arm[18:20] == (62).to_bytes(2, "little")  # EM_X86_64
    arm[18:20] = (183).to_bytes(2, "little")  # EM_AARCH64
    bad = with_library(fmu_dir, tmp_path, "arm.fmu", bytes(arm))
    refused(tmp_path, bad, f"{LIBRARY} is built for Aarch64 (64-bit), not for this machine (X86_64)")


def test_bytes_that_are_no_library_are_named_as_such(fmu_dir, tmp_path):  # noqa: F811
    bad = with_library(fmu_dir, tmp_path, "text.fmu", b"#!/bin/sh\necho not a library\n")
    refused(tmp_path, bad, f"{LIBRARY} is not an ELF shared library")


def lying_archive(src, dst, name="resources/zeros.bin", gib=5, declared=1000):
    """The archive `src` re-written by hand (every entry stored) plus `name`: `gib` GiB of zeros,
    deflated to ~5 MB, its headers declaring `declared` bytes and carrying the CRC of the true
    content. The deflate stream is one 64 MiB block flushed with Z_FULL_FLUSH, repeated: after a
    full flush the compressor forgets its history, so every repeat compresses to the same bytes."""
    import struct
    import zlib

    chunk = bytes(64 << 20)
    co = zlib.compressobj(9, zlib.DEFLATED, -15)
    block = co.compress(chunk) + co.flush(zlib.Z_FULL_FLUSH)
    repeats = (gib << 30) // len(chunk)
    crc = 0
    for _ in range(repeats):
        crc = zlib.crc32(chunk, crc)
    entries = []
    with zipfile.ZipFile(src) as z:
        for info in z.infolist():
            data = z.read(info)
            entries.append((info.filename, 0, zlib.crc32(data), data, len(data)))
    entries.append((name, 8, crc, None, declared))
    out, central = bytearray(), bytearray()
    with open(dst, "wb") as f:
        for fname, method, c, data, size in entries:
            offset = f.tell()
            comp = len(data) if data is not None else len(block) * repeats + 2
            n = fname.encode()
            f.write(struct.pack("<IHHHHHIIIHH", 0x04034B50, 20, 0, method, 0, 0x21, c, comp, size, len(n), 0) + n)
            if data is not None:
                f.write(data)
            else:
                for _ in range(repeats):
                    f.write(block)
                f.write(b"\x03\x00")  # the final, empty fixed-Huffman block
            central += struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 20, 20, 0, method, 0, 0x21, c, comp, size, len(n), 0, 0, 0, 0, 0, offset) + n
        start = f.tell()
        f.write(central)
        f.write(struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(entries), len(entries), len(central), start, 0))
    return dst


def test_an_entry_that_inflates_far_past_its_declared_size_is_refused(fmu_dir, tmp_path):  # noqa: F811
    """5 GiB of zeros declared as 1 000 bytes, with a correct CRC (before: extracted, 5.1 GB on
    disk, and run). The check counts the bytes it inflates and stops at 4 GiB."""
    bad = lying_archive(os.path.join(fmu_dir, "dc_motor_fmi2.fmu"), tmp_path / "bomb.fmu")
    assert bad.stat().st_size < 8 << 20
    with zipfile.ZipFile(bad) as z:  # a valid archive, its lie intact
        assert z.getinfo("resources/zeros.bin").file_size == 1000
    refused(tmp_path, bad, "unpacks to more than the 4294967296 bytes an FMU plant may (entry 'resources/zeros.bin' alone inflates past it)")
    assert not list(tmp_path.glob("**/zeros.bin"))
