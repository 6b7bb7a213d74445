# A/B of the release change: solver counts, solve time and the largest angle difference.
import json, csv, sys
def S(v): return json.load(open(f'{v}/summary.json'))
def A(v): return [float(r['angle_deg']) for r in csv.DictReader(open(f'{v}/angles.csv'))]
for v in ('old','new'):
    s=S(v); sv=s['solver']
    print(v, {k: sv.get(k) for k in ('states','rejected_time_steps','increments','cutbacks','newton_iterations','factorizations','krylov_iterations','release_attempts','direct_releases','assembly_s','factor_solve_s')}, s['timings'])
a,b=A('old'),A('new'); print('rows', len(a), len(b), 'max |angle diff| deg', max(abs(x-y) for x,y in zip(a,b)))
m_old=json.load(open('./old/metrics.json')); m_new=json.load(open('./new/metrics.json'))
print('nrmse old', [round(t['nrmse']*100,4) for t in m_old['trials']]); print('nrmse new', [round(t['nrmse']*100,4) for t in m_new['trials']])
