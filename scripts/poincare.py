"""Is a response periodic, period 2, period 3, or none of these?  From a simulate
run's time_series.csv: the Poincare section of T(0) (once per forcing period,
interpolated at t = k / f1) over the run's second half, its spread and its
period-2 and period-3 differences, and the six largest spectral peaks of T(0).

    .venv/bin/python scripts/poincare.py RUN/time_series.csv F1_HZ

A period-1 response has a Poincare spread near 0; period 2: |P_k - P_k+2| near 0
with a spread well above it, and a line at f1/2; period 3 likewise with P_k+3 and
lines at f1/3, 2 f1/3; otherwise quasi-periodic or irregular (docs/explanation/experiment.md).
"""
import sys, csv, numpy as np
path, f1 = sys.argv[1], float(sys.argv[2])
rows = np.array([[float(x) for x in r] for r in list(csv.reader(open(path)))[1:]])
t, T = rows[:, 0], rows[:, 5]
keep = t > t[-1] / 2
t, T = t[keep], T[keep]
# Poincare section: T(0) once per forcing period (interpolated at t = k / f1)
tk = np.arange(np.ceil(t[0] * f1), np.floor(t[-1] * f1)) / f1
P = np.interp(tk, t, T)
print(f"{len(P)} periods: Poincare T(0) spread {P.max() - P.min():.3f} N (mean {P.mean():.2f});"
      f" period-2 test |P_k - P_k+2| max {np.abs(P[2:] - P[:-2]).max():.3f} N, period-3 |P_k - P_k+3| max {np.abs(P[3:] - P[:-3]).max():.3f} N")
# spectrum of T(0): peaks not at multiples of f1
dt = np.median(np.diff(t)); x = T - T.mean()
F = np.abs(np.fft.rfft(x * np.hanning(len(x)))); f = np.fft.rfftfreq(len(x), dt)
idx = np.argsort(F)[::-1]
peaks = []
for i in idx:
    if all(abs(f[i] - g) > 0.2 for g, _ in peaks):
        peaks.append((f[i], F[i]))
    if len(peaks) == 6: break
print("spectral peaks (Hz, rel.):", ", ".join(f"{g:.3f} ({a / peaks[0][1]:.2f})" for g, a in peaks))
