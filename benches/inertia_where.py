import sys, math, numpy as np
sys.path.insert(0, "benches")
import eval_inertia_shaker as E
from contactlab.synthetic.rig import Virgin, masing_force
E.DRIVE = sys.argv[1]
label = sys.argv[2]; seed = int(sys.argv[3])
cond = [c for c in E.CONDITIONS if c[0] == label][0]
_, fs, f, cyc, xn, Fn, aca, share = cond
r0 = E.rig(cond, seed, 0.0, noise=False)
x, F, dt = r0.x, r0.F, 1/fs
b = r0.truth["base"]; h0, ac = b["h0"], b["ac"]
sx = xn*np.max(np.abs(x)); sF = Fn*np.max(np.abs(F))
def base(p): return masing_force(x, Virgin.exponential(p[0], p[1]))[0] + p[2]
p = np.array([h0, ac, 0.0]); F0 = base(p)
J = np.column_stack([(base(p + np.eye(3)[i]*s) - F0)/s for i, s in enumerate((h0*1e-6, ac*1e-6, h0*1e-6))])
v = np.gradient(x, dt, edge_order=2); a = E.acc_of(x, dt); dF = np.gradient(F0, dt, edge_order=2)
with np.errstate(divide="ignore", invalid="ignore"):
    k = np.where(np.abs(v) > 1e-12, dF/v, h0*ac)
k = np.clip(np.nan_to_num(k, nan=h0*ac), 0, h0*ac)
w = 1/(sF**2 + (k*sx)**2); sw = np.sqrt(w)
def perp(B, g):
    Q, _ = np.linalg.qr(B*sw[:, None]); gw = g*sw; return gw - Q@(Q.T@gw)
# what is x beyond a sine? fit sine+cos+const to steady part
t = np.arange(x.size)*dt
per = int(round(fs/f))
for name, R in (("none", None), ("kp", x), ("visc", v), ("delay", -dF)):
    B = J if R is None else np.column_stack([J, R])
    g = perp(B, a); tot = g@g
    c = np.cumsum(g*g)/tot
    idx = [int(per*q) for q in (0.05, 0.25, 0.5, 1, 2, 3)]
    print(name, "per_kg", f"{tot:.4g}", "cum share at cycles .05,.25,.5,1,2,3:", [f"{c[min(i,x.size-1)]:.3f}" for i in idx])
# per-cycle share and rms of a - (-w^2 x_centered)
w2 = (2*np.pi*f)**2
dev = a + w2*(x - x[per:].mean())
print("ẍ deviation from -ω²x RMS per cycle / ω²A:", [f"{np.sqrt(np.mean(dev[i*per:(i+1)*per]**2))/(w2*np.max(np.abs(x))):.4f}" for i in range(min(cyc,8))])
print("first 30 ms: x/A", np.round(x[:int(0.03*fs):int(0.003*fs)]/np.max(np.abs(x)),3))
print("v0/(Aω)", v[:5]/(np.max(np.abs(x))*2*np.pi*f))
