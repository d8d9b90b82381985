"""Garin et al. 2024, Tables 3 and 4, from Python: `onebeacon mc garin2024` as dicts, then
its mean error against T_com with matplotlib (pip install matplotlib; not a dependency)."""

import onebeacon

cells = onebeacon.mc("garin2024")  # Garin et al. Tables 3 and 4: 300 runs x 6 values of T_com
for c in cells:
    print(f'{c["sweep"]["t_com_s"]:>5} {c["estimator"]:<22} {c["mean_error_m"]:6.2f} {c["error_variance_m2"]:6.2f}')

import matplotlib.pyplot as plt  # not a dependency of onebeacon

for name in ("range+doppler", "rosb"):
    mine = [c for c in cells if c["estimator"] == name]
    plt.plot([c["sweep"]["t_com_s"] for c in mine], [c["mean_error_m"] for c in mine], "o-", label=name)
plt.xlabel("T_com (s)")
plt.ylabel("mean position error (m)")
plt.legend()
plt.savefig("garin.png")
