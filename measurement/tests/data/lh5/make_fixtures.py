"""Writes the LH5 fixtures of measurement/tests/lh5.rs with legend-pydataobj's writer
(legend-lh5io): one waveform table per file, 3 pulses x 5 samples, sample k (row-major) =
0.1 * k + bias_V * 1e-3 pC, dt = 4 ns.

Run: python make_fixtures.py measurement/tests/data/lh5 (with legend-pydataobj, legend-lh5io,
hdf5plugin installed). Written with legend-pydataobj 2.0.3, legend-lh5io 0.3.0, h5py 3.16.0."""
import sys
from pathlib import Path

import numpy as np
import hdf5plugin
import lh5
from lgdo import Array, ArrayOfEqualSizedArrays, Table, WaveformTable

out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
N, S, BIAS = 3, 5, 100.0


def table(dtype, dt_units="ns", dt=4.0):
    values = (0.1 * np.arange(N * S) + BIAS * 1e-3).reshape(N, S).astype(dtype)
    wf = WaveformTable(
        t0=np.zeros(N), t0_units="ns",
        dt=np.full(N, dt), dt_units=dt_units,
        values=ArrayOfEqualSizedArrays(nda=values), values_units="pC",
    )
    return Table(col_dict={"waveform": wf, "eventnumber": Array(np.arange(N))})


def write(name, t, **kw):
    lh5.write(t, name="raw", group="ch000", lh5_file=str(out / name), wo_mode="overwrite_file", **kw)
    (out / name).with_suffix(".toml").write_text(
        f'bias_V = {BIAS}\nsampling_period_ns = 4.0\ncharge_unit = "pC"\n')


write("gzip_f32.lh5", table(np.float32))            # the writer's default: chunked, shuffle + gzip
write("gzip_f64_us.lh5", table(np.float64, "us", 4e-3))
write("lzf_f32.lh5", table(np.float32), compression="lzf", shuffle=False)
write("contiguous_f64.lh5", table(np.float64), compression=None, shuffle=False, chunks=None)
write("zstd_f32.lh5", table(np.float32), compression=hdf5plugin.Zstd(), shuffle=False)

# LEGEND's encoded waveforms (ADC counts through a codec): the reader refuses them, naming the codec.
from lh5.compression import ULEB128ZigZagDiff, encode

counts = (np.arange(N * S) * 7 + 1000).reshape(N, S).astype(np.uint16)
wf = WaveformTable(t0=np.zeros(N), dt=np.full(N, 4.0), dt_units="ns",
                   values=ArrayOfEqualSizedArrays(nda=counts))
encoded = WaveformTable(t0=wf.t0, dt=wf.dt, values=encode(wf.values, ULEB128ZigZagDiff()))
write("encoded_uleb128.lh5", Table(col_dict={"waveform": encoded}))
