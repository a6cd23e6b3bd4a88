"""The seed paper's quantities for its 3-PUU, computed by pinmob.

Prints, for the generic configuration, each limb's constraint couple beside the
paper's eq. 20; and for the flat configuration (beta = 0), the paper's own
procedure (eqs. 30-38: generic couples with beta = 0 substituted) beside what the
wrenches at that configuration give.

Run: python examples/3puu_seed_paper.py
"""

from __future__ import annotations

import numpy as np

import pinmob


def paper_order(wrench: np.ndarray) -> str:
    """A wrench [f; tau] printed as the paper's row (L M N P Q R) = (f; tau)."""
    return "(" + " ".join(f"{x: .4f}" for x in np.round(wrench, 9) + 0.0) + ")"


def main() -> None:
    np.set_printoptions(precision=4, suppress=True)
    mech = pinmob.load("3-PUU")
    mob = pinmob.analyze(mech, "generic")
    beta = np.degrees(np.arctan2(0.2, 0.15))
    print(f"3-PUU generic, beta = {beta:.2f} deg for every limb")
    for limb in mob.limbs:
        w = limb.wrenches[:, 0] / np.linalg.norm(limb.wrenches[3:, 0])
        print(f"  limb {limb.name} constraint wrench {paper_order(w)}")
    print(f"  stacked-wrench singular values: {mob.singular_values}")
    print(f"  constraint rank {mob.constraint_rank}, DoF {mob.dof}: {mob.motion_type}  (paper, eq. 38: 3 translations)")

    flat = pinmob.load("3-PUU-flat")
    paper = pinmob.paper_view(flat, "flat")
    real = pinmob.analyze(flat, "flat")
    print("\n3-PUU-flat at beta = 0, the paper's procedure (eq. 20 with beta = 0 substituted):")
    print("  constraint space (eq. 34):")
    for c in paper.constraint_wrenches.T:
        print("   ", paper_order(c))
    print(f"  singular values {paper.singular_values}")
    print(f"  free space (eq. 37), DoF {paper.dof}: {paper.motion_type}")
    print("\nThe same configuration, wrenches computed from the Jacobians there:")
    for limb in real.limbs:
        joints = len(limb.joints)
        print(f"  limb {limb.name}: twist rank {limb.twist_rank} of {joints} joints, {limb.wrench_count} wrenches")
    print(f"  singular values {real.singular_values}")
    print(f"  constraint rank {real.constraint_rank}, DoF {real.dof}: {real.motion_type}")
    for m in real.motions:
        print(f"    {m.label}")


if __name__ == "__main__":
    main()
