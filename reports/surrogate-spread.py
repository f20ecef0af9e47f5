#!/usr/bin/env python3
# The ensemble-spread check of reports/surrogate.md: every third held-out sample through
# `hpge-cv predict --json` of the shipped ensemble; run from the repository root after `cargo build --release`.
import csv, json, subprocess, math
rows = list(csv.DictReader(open('./data/training/heldout.csv')))
names = ['d_li_mm','y1_bot','y2_bot','y3_bot','y4_bot','y1_top','y2_top','y3_top','y4_top']
out = []
for i, r in enumerate(rows):
    if r['status'] != 'ok' or i % 3: continue
    params = ','.join(f"{n}={r[n]}" for n in names)
    p = subprocess.run(['./target/release/hpge-cv','predict','--model','./models/super-siegfried-rz-paper-log-ensemble.safetensors','--params',params,'--voltages',r['U_B'],'--json'],capture_output=True,text=True)
    j = json.loads(p.stdout)
    c = j['c12_pf'][0]; s = j['ensemble_spread_pf'][0]; t = float(r['c12_pF'])
    out.append((abs(c-t)/t, s/c))
json.dump(out, open('/tmp/surrogate-spread.json','w'))
n = len(out)
big = [o for o in out if o[0] > 0.02]
print('n', n, 'err>2%', len(big))
for k in [1,2,3]:
    print('k',k,'all: |err|<=k*spread', sum(1 for e,s in out if e <= k*s)/n, 'of big:', sum(1 for e,s in big if e <= k*s)/max(1,len(big)))
# does spread flag big errors? fraction of big among top-10% spread
srt = sorted(out, key=lambda o: -o[1])
top = srt[:n//10]
print('top10% spread: frac err>2%', sum(1 for e,s in top if e>0.02)/len(top), ' overall', len(big)/n)
import statistics
print('median spread/c', statistics.median(s for e,s in out))
