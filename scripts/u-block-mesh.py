#!/usr/bin/env python3
# A large non-convex tet mesh for build-cost measurements (docs/benchmarks-history.md, "Detector
# points inside tets"): N = 88 gives 1,049,742 tets.
# U-shaped block of Kuhn-triangulated cubes (a non-convex solid no single point sees whole),
# written as Medit .mesh: scripts/u-block-mesh.py N out.mesh  (N x N/3 x N cubes minus the slot).
import sys
n = int(sys.argv[1]); ny = n // 3
inside = lambda i, j, k: 0 <= i < n and 0 <= j < ny and 0 <= k < n and not (n // 3 <= i < 2 * n // 3 and k >= n // 3)
idx = lambda i, j, k: (i * (ny + 1) + j) * (n + 1) + k
used = {}
tets = []
perms = ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0))
for i in range(n):
    for j in range(ny):
        for k in range(n):
            if not inside(i, j, k): continue
            for p in perms:
                cur = [i, j, k]; path = [tuple(cur)]
                for ax in p:
                    cur[ax] += 1; path.append(tuple(cur))
                t = [used.setdefault(v, len(used)) for v in path]
                # the Kuhn simplex orientation is the permutation's sign
                sign = 1 if p in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1
                if sign < 0: t[2], t[3] = t[3], t[2]
                tets.append(t)
with open(sys.argv[2], "w") as f:
    f.write("MeshVersionFormatted 1\nDimension 3\nVertices\n%d\n" % len(used))
    for v, _ in sorted(used.items(), key=lambda e: e[1]):
        f.write("%g %g %g 0\n" % (v[0] / n, v[1] / n, v[2] / n))
    f.write("Tetrahedra\n%d\n" % len(tets))
    for t in tets: f.write("%d %d %d %d 0\n" % tuple(x + 1 for x in t))
    f.write("End\n")
