"""ROSS 3.1 reference of a rotor on pedestals (bearings with ``n_link`` to point masses on their own bearings).

Runs ONLY with Python >= 3.13 and ``ross-rotordynamics`` 3.1 (the trixie chroot of docs/response.md):

    cp studies/rotor/ross_pedestal.py /work/trixie/tmp/ && \
        chroot /work/trixie /opt/ross/bin/python /tmp/ross_pedestal.py | sed -n "/^{/,$p" > tests/data/ross/pedestal.json

The rotor is ROSS's ``rotor_example()`` (tests/data/ross/rotor_example.toml) with its bearings at nodes 0 and 6
linked to pedestal nodes 7 and 8 (20 kg point masses on bearings kxx = 5 MN/m, kyy = 4 MN/m).
"""
import json

import numpy as np
import ross as rs

steel = rs.Material(name="steel_pedestal", rho=7810, E=211e9, G_s=81.2e9)
shaft = [rs.ShaftElement(L=0.25, idl=0.0, odl=0.05, material=steel, shear_effects=True, rotary_inertia=True,
                         gyroscopic=True) for _ in range(6)]
disks = [rs.DiskElement.from_geometry(n=n, material=steel, width=0.07, i_d=0.05, o_d=0.28) for n in (2, 4)]
bearings = [rs.BearingElement(n=0, kxx=1e6, kyy=0.8e6, cxx=0, n_link=7),
            rs.BearingElement(n=6, kxx=1e6, kyy=0.8e6, cxx=0, n_link=8),
            rs.BearingElement(n=7, kxx=5e6, kyy=4e6, cxx=0),
            rs.BearingElement(n=8, kxx=5e6, kyy=4e6, cxx=0)]
masses = [rs.PointMass(n=7, m=20.0), rs.PointMass(n=8, m=20.0)]
rotor = rs.Rotor(shaft, disks, bearings, masses)
out = {"ross": rs.__version__}
for speed in (0.0, 400.0):
    m = rotor.run_modal(speed=speed, num_modes=16)
    out[f"modal_{speed:g}"] = {"speed": speed, "wd": np.asarray(m.wd).tolist(),
                               "whirl": [str(w) for w in m.whirl_direction()]}
print(json.dumps(out, indent=1))
