"""Print the RGB (eta, k) that Mitsuba 3's RGB variants use for each named
conductor of `roughconductor` (the table `CONDUCTORS` in
crates/lobe/src/ior.rs). Needs `pip install mitsuba`; not run by CI.

    python3 bench/mitsuba_conductors.py
"""

import mitsuba as mi

mi.set_variant("scalar_rgb")
mi.set_log_level(mi.LogLevel.Error)  # its warnings (out-of-gamut clamps) go to stdout
NAMES = """a-C Ag Al AlAs AlAs_palik AlSb AlSb_palik Au Be Be_palik Cr CsI CsI_palik Cu Cu_palik Cu2O Cu2O_palik CuO
CuO_palik d-C d-C_palik Hg Hg_palik HgTe HgTe_palik Ir Ir_palik K K_palik Li Li_palik MgO MgO_palik Mo Mo_palik
Na_palik Nb Nb_palik Ni_palik Rh Rh_palik Se Se_palik SiC SiC_palik SnTe SnTe_palik Ta Ta_palik Te Te_palik ThF4
ThF4_palik TiC TiC_palik TiN TiN_palik TiO2 TiO2_palik VC VC_palik V_palik VN VN_palik W W_palik""".split()

print(f"# Mitsuba {mi.__version__}, scalar_rgb")
for name in NAMES:
    try:
        p = mi.traverse(mi.load_dict({"type": "roughconductor", "material": name}))
    except Exception as e:  # a name this Mitsuba does not load (W_palik in 3.9.1)
        print(f"# {name}: not loaded ({str(e).splitlines()[0][:80]})")
        continue
    eta, k = list(p["eta.value"]), list(p["k.value"])
    fmt = lambda v: ", ".join(repr(float(f"{x:.6g}")) for x in v)  # noqa: E731
    print(f'    ("{name}", [{fmt(eta)}], [{fmt(k)}]),')
