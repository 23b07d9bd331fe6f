# Generates samples/robot/*.csv (run from the project root): deterministic synthetic calibration tables.
import math
class Lcg:
    def __init__(s, seed): s.x = seed
    def next(s):
        s.x = (s.x * 6364136223846793005 + 1442695040888963407) % 2**64
        return (s.x >> 11) / float(1 << 53)
    def range(s, lo, hi): return lo + (hi - lo) * s.next()
    def normal(s):
        u = max(s.next(), 1e-300); v = s.next()
        return math.sqrt(-2 * math.log(u)) * math.cos(2 * math.pi * v)
def qmul(a, b):
    w1,x1,y1,z1 = a; w2,x2,y2,z2 = b
    return (w1*w2-x1*x2-y1*y2-z1*z2, w1*x2+x1*w2+y1*z2-z1*y2, w1*y2-x1*z2+y1*w2+z1*x2, w1*z2+x1*y2-y1*x2+z1*w2)
def qaxis(ax, ang):
    s = math.sin(ang/2); return (math.cos(ang/2), ax[0]*s, ax[1]*s, ax[2]*s)
def qrot(q, v):
    p = (0.0,)+tuple(v); qc = (q[0],-q[1],-q[2],-q[3])
    r = qmul(qmul(q,p),qc); return r[1:]
rng = Lcg(7)
tip = (3.2, -1.7, 145.0); pivot = (512.0, -80.0, 210.0)
rows = []
for _ in range(12):
    d = rng.range(0, 2*math.pi)
    q = qmul(qaxis((math.cos(d), math.sin(d), 0.0), math.radians(rng.range(25, 45))), qaxis((0,0,1), rng.range(-3, 3)))
    rt = qrot(q, tip)
    p = [pivot[i] - rt[i] + 0.02*rng.normal() for i in range(3)]
    rows.append(p + list(q))
with open("samples/robot/pivot.csv", "w") as f:
    f.write("# flange poses of a nozzle tip held on one point, robot base frame\n")
    f.write("x,y,z,qw,qx,qy,qz\n")
    for r in rows: f.write(",".join("%.6f" % v for v in r) + "\n")
# register: 10 scanner points and the same points in the robot frame (rotated 30 deg about z, shifted), 0.02 mm noise
q = qaxis((0,0,1), math.radians(30)); t = (420.0, -35.0, 12.5)
a = []; b = []
for i in range(10):
    p = (rng.range(-40, 40), rng.range(-40, 40), rng.range(0, 15))
    r = qrot(q, p)
    a.append(p); b.append(tuple(r[k] + t[k] + 0.02*rng.normal() for k in range(3)))
for name, pts, what in (("scanner_points.csv", a, "scanner"), ("robot_points.csv", b, "robot base")):
    with open("samples/robot/" + name, "w") as f:
        f.write("x,y,z\n")
        for p in pts: f.write("%.6f,%.6f,%.6f\n" % p)
