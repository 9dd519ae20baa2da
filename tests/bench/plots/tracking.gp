# Head prediction against tracker latency (series.py tracking): one block per
# prediction (none, constant velocity, double exponential at alpha 0.3, 0.5,
# 0.7, 0.9); rows latency ms, the eyes' error median and p99 mm.
width = 900; height = 560
load dir.'/style.gp'
set title "Head prediction: the eyes against the walking head at display time\n(60 Hz tracker and display, 0.5 mm jitter; solid median, dashed p99)"
set xlabel "the tracker's latency (ms)"
set ylabel 'error of the eyes (mm)'
set logscale y
set key top left font ',9'
name(b) = b == 0 ? 'none' : b == 1 ? 'constant velocity' : sprintf('double exponential, alpha 0.%d', b == 2 ? 3 : b == 3 ? 5 : b == 4 ? 7 : 9)
plot for [b = 0:5] data index b using 1:2 with linespoints lt (b + 1) title name(b), \
     for [b = 0:5] data index b using 1:3 with lines lt (b + 1) dt 2 notitle
