"""Tables of the shear split from results.json (probe.py's rows): python analyse.py [--markdown]."""

from __future__ import annotations

import json
import sys
from pathlib import Path

REGIONS = ("front", "rear", "front_up", "rear_up")
KINDS = ("stuck", "carried", "outside", "gap", "lateral")


def derived(r: dict) -> dict:
    fz, a = r["Fz"], r["contact_shear_area"]
    tau = r["contact_shear_capacity"] / a if a > 0 else float("nan")
    kappa = r["kappa_coating_Pa"] if r["scene"] == "coated" else r["kappa_substrate_Pa"]
    axy_front = r["contact_area_xy_front"] + r["contact_area_xy_front_up"]
    d = {"mu_sh": r["Fx_sh"] / fz, "mu_sh_ana": r["analytical_mu_sh"], "A_um2": a * 1e12,
         "Axy_ana_um2": r["analytical_Axy"] * 1e12, "Axy_front_um2": axy_front * 1e12,
         "Axy_all_um2": r["contact_area_xy"] * 1e12,
         "tau_over_fkappa": tau / (r["f"] * kappa) if r["f"] > 0 else float("nan"),
         # F_sh / sum tau A: the slip's direction and stuck nodes
         "efficiency": r["Fx_sh"] / r["contact_shear_capacity"] if r["f"] > 0 else float("nan"),
         # the paper's reading on the MPM's own contact: F_sh = tau x the front half's projection
         "mu_sh_paper_own": tau * axy_front / fz,
         "mu_sh_tauA": tau * a / fz,  # every node traction-limited along x
         "hardness_front": r["Fz"] / axy_front if axy_front > 0 else float("nan")}
    for reg in REGIONS:
        d[f"A_{reg}"] = r[f"contact_area_{reg}"] / a
        d[f"mu_sh_{reg}"] = r[f"contact_fx_sh_{reg}"] / fz
        d[f"Fz_{reg}"] = r[f"contact_fz_pl_{reg}"] / fz
    for k in KINDS:
        d[f"A_{k}"] = r[f"contact_area_{k}"] / a
        d[f"mu_sh_{k}"] = r[f"contact_fx_sh_{k}"] / fz
    return d


def main() -> None:
    rows = json.loads((Path(__file__).resolve().parent / "results.json").read_text())["runs"]
    md = "--markdown" in sys.argv
    for r in rows:
        d = derived(r)
        head = f"{r['scene']} f={r['f']:g} h={r['h_um']:g}"
        if md:
            rear = d["mu_sh_rear"] + d["mu_sh_rear_up"]
            up = d["mu_sh_front_up"] + d["mu_sh_rear_up"]
            mu_paper = r["mu_pl"] + d["mu_sh_paper_own"]
            print(f"| {r['scene']} | {r['f']:g} | {r['h_um']:g} | {r['mu']:.3f} | {d['mu_sh']:.3f} "
                  f"({d['mu_sh_ana']:.3f}) | {d['A_um2'] / d['Axy_ana_um2']:.2f} | "
                  f"{d['Axy_front_um2'] / d['Axy_ana_um2']:.2f} | {d['hardness_front'] / 1e6:.0f} | "
                  f"{d['efficiency']:.2f} | {d['tau_over_fkappa']:.2f} | {rear:.3f} | {up:.3f} | "
                  f"{d['A_carried']:.2f} | {d['A_outside']:.2f} | {d['A_stuck']:.2f} | "
                  f"{d['mu_sh_paper_own']:.3f} | {mu_paper:.3f} ({r['analytical_mu']:.3f}) | "
                  f"{r['depth'] * 1e6:.1f} | {int(r['steady'])} |")
            continue
        print(f"{head}: mu {r['mu']:.3f} mu_sh {d['mu_sh']:.3f} (ana {d['mu_sh_ana']:.3f}) Fz {r['Fz']:.2f} N "
              f"depth {r['depth'] * 1e6:.1f} um dp {r['dp'] * 1e6:.1f} um steady {r['steady']:.0f}")
        print(f"   area {d['A_um2']:.0f} um2; xy all {d['Axy_all_um2']:.0f} front {d['Axy_front_um2']:.0f} ana "
              f"{d['Axy_ana_um2']:.0f}; tau/(f kappa) {d['tau_over_fkappa']:.3f} eff {d['efficiency']:.3f} "
              f"mu_sh(tau A) {d['mu_sh_tauA']:.3f} paper-own {d['mu_sh_paper_own']:.3f} H_front "
              f"{d['hardness_front'] / 1e6:.0f} MPa")
        print("   regions A/mu_sh/Fz: " + "  ".join(f"{g} {d[f'A_{g}']:.2f}/{d[f'mu_sh_{g}']:.3f}/{d[f'Fz_{g}']:.2f}"
                                               for g in REGIONS))
        print("   kinds A/mu_sh: " + "  ".join(f"{k} {d[f'A_{k}']:.2f}/{d[f'mu_sh_{k}']:.3f}" for k in KINDS))


if __name__ == "__main__":
    main()
