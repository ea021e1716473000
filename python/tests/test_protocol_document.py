"""PROTOCOL.md against the kit: the header's layout (§4's table), its type name, the protocol
version, and the service settings of §4 — parsed out of the document, so the document is
checked too."""

import ctypes
import os
import re

from conftest import REPO

from uio_component import PROTOCOL_VERSION, wire
from uio_component.wire import Header

DOC = open(os.path.join(REPO, "PROTOCOL.md"), encoding="utf-8").read()
SECTION4 = DOC[DOC.index("## 4."):DOC.index("## 5.")]

CTYPES = {"u64": ctypes.c_uint64, "f64": ctypes.c_double, "u32": ctypes.c_uint32}


def header_table():
    """(offset, size, field, type) of every row of §4's header table."""
    rows = re.findall(r"^\s*\|\s*(\d+)\s*\|\s*(\d+)\s*\|\s*`(\w+):\s*(\w+)`\s*\|", SECTION4, re.M)
    return [(int(o), int(s), f, t) for o, s, f, t in rows]


def test_the_document_has_a_header_table():
    assert [r[2] for r in header_table()] == ["step", "sim_time", "sent_ns", "taken_ns", "protocol", "reserved"]


def test_header_fields_sit_at_the_documented_offsets():
    table = header_table()
    assert [name for name, _ in Header._fields_] == [r[2] for r in table]
    for offset, size, name, typ in table:
        field = getattr(Header, name)
        assert field.offset == offset, name
        assert field.size == size, name
        assert dict(Header._fields_)[name] is CTYPES[typ], name
        assert ctypes.sizeof(CTYPES[typ]) == size, name


def test_header_size_alignment_and_type_name():
    m = re.search(r"user header\*\*\s+`([\w:]+)`.*?(\d+) bytes, align (\d+)", SECTION4, re.S)
    assert m, "§4 names the user header, its size and alignment"
    type_name, size, align = m.group(1), int(m.group(2)), int(m.group(3))
    assert Header.type_name() == type_name == "uio_observers::Header"
    assert ctypes.sizeof(Header) == size == 40
    assert ctypes.alignment(Header) == align == 8
    table = header_table()
    assert table[-1][0] + table[-1][1] == size


def test_protocol_version():
    assert re.search(r"^# The lockstep protocol, version (\d+)", DOC, re.M).group(1) == str(PROTOCOL_VERSION)
    assert "`protocol: u32` | 1 |" in SECTION4.replace("  ", " ")


def test_payload_is_a_slice_of_f64():
    assert "a slice of `f64` (iceoryx2 type name `f64`" in SECTION4
    assert wire.iox2.get_type_name(ctypes.c_double) == "f64"


def test_service_settings():
    text = " ".join(SECTION4.split())
    m = re.search(r"at most (\d+) publisher, (\d+) subscribers and (\d+) nodes; history (\d+); "
                  r"subscriber buffer up to (\d+) samples", text)
    assert m
    assert tuple(int(g) for g in m.groups()) == (wire.MAX_PUBLISHERS, wire.MAX_SUBSCRIBERS, wire.MAX_NODES,
                                                 wire.HISTORY_SIZE, wire.SUBSCRIBER_MAX_BUFFER_SIZE)
    assert "no safe overflow" in text
    assert int(re.search(r"lockstep input use a buffer of (\d+)", text).group(1)) == wire.SUBSCRIBER_BUFFER_SIZE
    assert re.search(r"publishers allow (one|1) loaned sample", text) and wire.MAX_LOANED_SAMPLES == 1
    m = re.search(r"`<service>/wake` \((\d+) notifier, (\d+) listeners, (\d+) nodes\)", text)
    assert m
    assert tuple(int(g) for g in m.groups()) == (wire.EVENT_MAX_NOTIFIERS, wire.EVENT_MAX_LISTENERS, wire.EVENT_MAX_NODES)
    for wait in re.search(r"notifies it when the configuration's `wait` is (.*?); with", text).group(1).replace(" or ", ", ").split(", "):
        assert wire.needs_events(wait.strip("` ")), wait
    for wait in ("yield", "sleep:100", "spin-then-yield:500"):
        assert not wire.needs_events(wait)
