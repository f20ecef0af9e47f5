import csv,sys
def rd(p):
    return {float(r['voltage_V']):float(r['c12_pF']) for r in csv.DictReader(l for l in open(p) if not l.startswith('#'))}
a=rd(sys.argv[1]); b=rd(sys.argv[2])
print(sys.argv[1].split('/')[-1], 'vs', sys.argv[2].split('/')[-1], 'max |rel|', max(abs(b[v]/a[v]-1) for v in a))
