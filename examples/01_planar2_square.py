"""Plan the 2-DoF arm around one square with coal and with GraphDistNet constraints.

python examples/01_planar2_square.py
"""

import gdnplan as gp

problem = gp.Problem.from_toml("problems/planar2_square.toml")
for collision in ("coal", "graphdistnet"):
    result = gp.plan(problem, collision=collision)
    print(
        f"{collision:>12}: certified {result.success}, clearance {result.min_distance:+.4f} m, "
        f"{result.solve_time:.2f} s, path cost {result.path_cost:.3f} rad²"
    )
