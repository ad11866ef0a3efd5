import numpy as np
import pytest

from plough.analytical import PAPER_FITS, ploughing, ploughing_dataset, power_law_friction


def test_power_law_equations():
    fit = PAPER_FITS[3.0]
    loads = np.array([1.0, 22.0, 46.0])
    res = power_law_friction(loads, fit)
    np.testing.assert_allclose(res.dp, 4.7e-6 * loads**0.85, rtol=1e-14)
    np.testing.assert_allclose(res.Ayz, 0.15 * res.dp**1.5, rtol=1e-14)
    np.testing.assert_allclose(res.Axy, 0.0046 * res.dp**0.999, rtol=1e-14)
    np.testing.assert_allclose(res.mu_pl, 255e6 * res.Ayz / loads, rtol=1e-14)
    # eq 9.2 is tau * Axy / Fn with tau = Cp (Fn / Axy)^np
    np.testing.assert_allclose(res.mu_sh, 0.32 * (loads / res.Axy) ** 0.95 * res.Axy / loads, rtol=1e-12)
    with pytest.raises(ValueError, match="load_N = 0 N"):
        power_law_friction(0.0, fit)


def test_dataset_matches_direct_calls_and_has_units():
    ds = ploughing_dataset({"thickness_m": [0.0, 4e-6, 16e-6], "hardness_ratio": [0.5, 2.0]},
                           load_N=5.0, radius_m=0.5e-3, substrate_hardness_Pa=450e6, k1=12.5)
    assert ds["mu"].dims == ("thickness_m", "hardness_ratio")
    for name, var in ds.variables.items():
        assert "units" in var.attrs and "long_name" in var.attrs, name
    direct = ploughing(5.0, 0.5e-3, 16e-6, 2.0 * 450e6, 450e6, k1=12.5)
    assert float(ds["mu"].sel(thickness_m=16e-6, hardness_ratio=2.0)) == direct.mu
    assert ds["coating_worn"].dtype == bool
    with pytest.raises(ValueError, match="unknown"):
        ploughing_dataset({"colour": [1.0]})
