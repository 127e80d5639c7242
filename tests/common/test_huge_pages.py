"""`kernels.common.huge_pages`: when huge pages are asked for, and that the advice reaches the kernel (kernels)."""

import mmap
import sys

import numpy as np
import pytest
from tessera.kernels.common import huge_pages


def fake_sys(root, balloon_features=None, other_features=None, hv_balloon=False, thp="always [madvise] never"):
    """A ``/sys`` tree with a THP setting, optionally a virtio balloon and another virtio device (features: strings
    of 0/1, bit i at index i), and optionally a bound Hyper-V balloon driver."""
    mm = root / "kernel/mm/transparent_hugepage"
    mm.mkdir(parents=True)
    (mm / "enabled").write_text(thp + "\n")
    devices = root / "bus/virtio/devices"
    devices.mkdir(parents=True)
    for i, (kind, features) in enumerate(((5, balloon_features), (1, other_features))):
        if features is not None:
            d = devices / f"virtio{i}"
            d.mkdir()
            (d / "device").write_text(f"0x{kind:04x}\n")
            (d / "features").write_text(features + "\n")
    if hv_balloon:
        driver = root / "bus/vmbus/drivers/hv_balloon"
        driver.mkdir(parents=True)
        (driver / "bind").write_text("")
        (driver / "1eccfd72-4b41-45ef-b73a-4a6e44c12924").symlink_to(root)
    return root


REPORTING = "0110010100" + "0" * 54  # the balloon of the development VM: bit 5 (free page reporting) set
NOT_REPORTING = "0110000100" + "0" * 54


@pytest.mark.parametrize(("kwargs", "reports"), [
    ({}, False),
    ({"balloon_features": REPORTING}, True),
    ({"balloon_features": NOT_REPORTING}, False),
    ({"other_features": REPORTING}, False),  # bit 5 of a network card means something else
    ({"hv_balloon": True}, True),
])
def test_machines_that_hand_free_memory_to_a_hypervisor_are_recognised(tmp_path, kwargs, reports):
    assert huge_pages.reports_free_pages(fake_sys(tmp_path, **kwargs)) is reports


@pytest.mark.parametrize(("setting", "offered"), [("always [madvise] never", True), ("[always] madvise never", True),
                                                  ("always madvise [never]", False)])
def test_the_kernels_huge_page_setting_is_read(tmp_path, setting, offered):
    assert huge_pages.thp_offered(fake_sys(tmp_path, thp=setting)) is offered
    assert huge_pages.thp_offered(tmp_path / "missing") is False


def test_the_environment_overrides_the_automatic_choice(monkeypatch):
    monkeypatch.setenv("TESSERA_HUGE_PAGES", "off")
    assert huge_pages.enabled() is False
    monkeypatch.setenv("TESSERA_HUGE_PAGES", "on")
    assert huge_pages.enabled() is sys.platform.startswith("linux")
    monkeypatch.setenv("TESSERA_HUGE_PAGES", "auto")
    assert huge_pages.enabled() is huge_pages.auto_choice()


@pytest.mark.skipif(not sys.platform.startswith("linux") or not huge_pages.thp_offered("/sys"),
                    reason="needs Linux with transparent huge pages offered")
def test_advice_reaches_the_kernel_for_whole_huge_pages_only(monkeypatch):
    """Advised, the 2 MiB pages inside a new array carry the kernel's ``hg`` flag and the partial ones at its ends do
    not; small arrays, and any array with the advice off, are left alone; the values written afterwards are kept."""
    region = mmap.mmap(-1, 16 << 20, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
    base = np.frombuffer(region, np.uint8).ctypes.data
    start = -(-base // huge_pages.HUGE_PAGE) * huge_pages.HUGE_PAGE + 4096  # an array not aligned to 2 MiB
    length = 9 << 20
    monkeypatch.setenv("TESSERA_HUGE_PAGES", "off")
    assert huge_pages.advise(start, length) is False
    assert "hg" not in huge_pages.vm_flags(start + length // 2)
    monkeypatch.setenv("TESSERA_HUGE_PAGES", "on")
    assert huge_pages.advise(start, huge_pages.MIN_BYTES - 1) is False
    assert "hg" not in huge_pages.vm_flags(start + length // 2)
    assert huge_pages.advise(start, length) is True
    first = start - 4096 + huge_pages.HUGE_PAGE  # the first whole 2 MiB page inside the array
    assert "hg" in huge_pages.vm_flags(first)
    assert "hg" in huge_pages.vm_flags(first + 3 * huge_pages.HUGE_PAGE - 1)  # the last whole one
    assert "hg" not in huge_pages.vm_flags(first - 1)  # the partial page at the start
    assert "hg" not in huge_pages.vm_flags(first + 3 * huge_pages.HUGE_PAGE)  # the partial page at the end
    values = np.frombuffer(region, np.float32)
    values[:] = np.arange(len(values), dtype=np.float32)
    assert np.array_equal(values, np.arange(len(values), dtype=np.float32))
    del values
    region.close()
