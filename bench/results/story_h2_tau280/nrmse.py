# Recomputes the paper metrics (NRMSE of the 2.5 s-mark angles vs the ideal model, spreads)
# from angles.csv and ideal_angles.csv: python3 nrmse.py angles.csv ideal_angles.csv (stdlib only).
import sys, csv, math
def load(p):
    d={}
    for r in csv.DictReader(open(p)):
        d.setdefault(int(r['trial']),[]).append((float(r['time_s']),float(r['pressure_kPa']),float(r['angle_deg'])))
    return d
a=load(sys.argv[1]); ref=load(sys.argv[2])[1]
rm=[x[2] for x in ref[0::2]]
rng=max(rm)-min(rm)
for t,rows in sorted(a.items()):
    if len(rows)<len(ref): continue
    mk=[x[2] for x in rows[0::2]]; en=[x[2] for x in rows[1::2]]
    e=math.sqrt(sum((m-r)**2 for m,r in zip(mk,rm))/len(rm))/rng
    print(t, 'NRMSE %.2f %%'%(100*e), 'spread top3', ['%.1f'%(en[i]-mk[i]) for i in (7,8,9)], 'max low(0-15) err %.2f'%max(abs(mk[i]-rm[i]) for i in range(4)))
