#!/usr/bin/env python3
"""Statistics of rnx2rtkp ECEF solutions (out-solformat=xyz) against the ABPO header
position, as sdins_sim::nav::spp::run_spp computes them: NED errors through C_e^n at the
reference (WGS-84), horizontal and vertical RMS, nearest-rank 95th percentiles, mean per
axis. Usage: python3 tools/rtklib_fixture/pos_stats.py FILE.pos [...]"""
import sys, math
X0=(4097216.6805,4429119.0287,-2065771.3676)
a=6378137.0; f=1/298.257223563; e2=f*(2-f)
x,y,z=X0; lon=math.atan2(y,x); p=math.hypot(x,y); lat=math.atan2(z,p*(1-e2))
for _ in range(10):
    N=a/math.sqrt(1-e2*math.sin(lat)**2); h=p/math.cos(lat)-N; lat=math.atan2(z,p*(1-e2*N/(N+h)))
sl,cl,so,co=math.sin(lat),math.cos(lat),math.sin(lon),math.cos(lon)
def ned(d):
    return (-sl*co*d[0]-sl*so*d[1]+cl*d[2], -so*d[0]+co*d[1], -cl*co*d[0]-cl*so*d[1]-sl*d[2])
for fn in sys.argv[1:]:
    E=[]
    for l in open(fn):
        if l.startswith('%'): continue
        t=l.split(); r=[float(v) for v in t[2:5]]
        E.append(ned([r[i]-X0[i] for i in range(3)]))
    n=len(E); h=sorted(math.hypot(e[0],e[1]) for e in E); v=sorted(abs(e[2]) for e in E)
    rms=lambda s: math.sqrt(sum(q*q for q in s)/n)
    p95=lambda s: s[max(0,math.ceil(0.95*n)-1)]
    mean=[sum(e[k] for e in E)/n for k in range(3)]
    print(f"{fn}: n={n} H_rms={rms(h):.2f} H95={p95(h):.2f} V_rms={rms(v):.2f} V95={p95(v):.2f} mean_NED=[{mean[0]:.2f}, {mean[1]:.2f}, {mean[2]:.2f}]")
