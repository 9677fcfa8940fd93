"""SymPy baseline for the seed-ac derivation: the same 44 gains derived with SymPy.

The way an engineer writes it without rtest: build the seed's HTMs with all 44 error symbols
(small-angle matrices as printed in the seed), multiply the chains, take the error vector
R_tool^T (P_tool - P_work), differentiate with respect to every error at zero and simplify.
Prints the wall time. Reproduce: `pip install sympy && python3 benches/sympy_baseline.py`.
Compare with `cargo bench -p benches --bench generate` (derive/seed-ac).
"""
import time
import sympy as sp

t0 = time.perf_counter()
Xm, Ym, Zm, a, c = sp.symbols("Xm Ym Zm a c")
Xa, Ya, Za, Zc, Xw, Yw, Zw, Xz, Yz, Zz, Xh, Zh, Zp = sp.symbols("Xa Ya Za Zc Xw Yw Zw Xz Yz Zz Xh Zh Zp")
names = ("EXX EYX EZX EAX EBX ECX EXY EYY EZY EAY EBY ECY EXZ EYZ EZZ EAZ EBZ ECZ COX AOZ BOZ "
         "XOW YOW ZOW EXA EYA EZA EAA EBA ECA YOA ZOA BOA COA EXC EYC EZC EAC EBC ECC XOC YOC AOC BOC").split()
E = {n: sp.Symbol(n) for n in names}


def trans(x, y, z):
    return sp.Matrix([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def small(ax, by, cz, x=0, y=0, z=0):
    return sp.Matrix([[1, -cz, by, x], [cz, 1, -ax, y], [-by, ax, 1, z], [0, 0, 0, 1]])


def rx(t):
    return sp.Matrix([[1, 0, 0, 0], [0, sp.cos(t), -sp.sin(t), 0], [0, sp.sin(t), sp.cos(t), 0], [0, 0, 0, 1]])


def rz(t):
    return sp.Matrix([[sp.cos(t), -sp.sin(t), 0, 0], [sp.sin(t), sp.cos(t), 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


Tx = small(0, 0, E["COX"]) * trans(Xm, 0, 0) * small(E["EAX"], E["EBX"], E["ECX"], E["EXX"], E["EYX"], E["EZX"])
Ta = trans(Xa, Ya, Za) * small(0, E["BOA"], E["COA"], 0, E["YOA"], E["ZOA"]) * small(0, E["EBA"], E["ECA"], E["EXA"], E["EYA"], E["EZA"]) * rx(a + E["EAA"])
Tc = trans(0, 0, Zc) * small(E["AOC"], E["BOC"], 0, E["XOC"], E["YOC"], 0) * small(E["EAC"], E["EBC"], 0, E["EXC"], E["EYC"], E["EZC"]) * rz(c + E["ECC"])
Tw = trans(Xw, Yw, Zw) * trans(E["XOW"], E["YOW"], E["ZOW"])
Ty = trans(0, Ym, 0) * small(E["EAY"], E["EBY"], E["ECY"], E["EXY"], E["EYY"], E["EZY"])
Tz = trans(Xz, Yz, Zz) * small(E["AOZ"], E["BOZ"], 0) * trans(0, 0, Zm) * small(E["EAZ"], E["EBZ"], E["ECZ"], E["EXZ"], E["EYZ"], E["EZZ"])
Tp = trans(Xh, 0, Zh) * trans(0, 0, Zp)

work = Tx * Ta * Tc * Tw
tool = Ty * Tz * Tp
e = (tool[:3, :3].T * (tool[:3, 3] - work[:3, 3]))
zero = {s: 0 for s in E.values()}
gains = {}
for n in names:
    gains[n] = [sp.simplify(sp.diff(e[k], E[n]).subs(zero)) for k in range(3)]
t1 = time.perf_counter()
print(f"sympy {sp.__version__}: 44 position gains of seed-ac in {t1 - t0:.2f} s")
print("BOA:", gains["BOA"])
