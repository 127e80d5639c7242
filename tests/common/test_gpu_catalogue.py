"""Every shader Tessera compiles (tier: gpu): each create-info keeps its push constants within the 128 bytes that
Vulkan and Metal guarantee (Blender warns as they are declared), and the self-test compiles them all on the running
backend and says so."""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def test_every_create_info_keeps_its_push_constants_within_128_bytes(addon_module, gpu_renderer, capfd):
    catalogue = addon_module("gpu_shaders.catalogue")
    describers = catalogue.describers()
    assert len(describers) == len(catalogue.SHADERS) >= 12
    for name, describe in describers.items():
        capfd.readouterr()
        describe()
        out = capfd.readouterr()
        assert "Push constants" not in out.out + out.err, (name, out.out + out.err)


def test_the_self_test_compiles_every_shader_on_this_backend(addon_module, gpu_renderer, capfd):
    from conftest import GPU_BACKEND

    selftest = addon_module("addon.gpu_selftest")
    backend, results = selftest.run()
    assert backend.split()[0] == GPU_BACKEND  # the backend asked for is the one running (the switch took)
    assert results and all(why == "" for why in results.values()), results
    with pytest.raises(SystemExit) as done:
        selftest.main()
    assert done.value.code == 0
    out = capfd.readouterr().out
    assert f"{len(results)} of {len(results)} shaders compile" in out and "FAIL" not in out
