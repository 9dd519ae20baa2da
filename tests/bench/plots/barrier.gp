# Barrier round and present skew against the node count (series.py barrier).
# Columns: nodes, then (median, min, max over runs) of barrier median, barrier p99,
# ready/go median, ready/go p99, present skew median, present skew p99.
width = 1200; height = 480
load dir.'/style.gp'
set multiplot layout 1,2 title "Frame barrier on one machine (null-render nodes, loopback): median over runs, bars min–max over runs"
set logscale xy 2
set logscale y 10
set xrange [0.8:80]
set xtics (1, 2, 4, 8, 16, 32, 64)
set format y '%g'
set xlabel 'render nodes'
set ylabel 'time (µs)'
set title 'Barrier round: last node ready → go'
plot data using 1:2:3:4 with yerrorlines lt 1 title 'optique, median frame', \
     '' using 1:5:6:7 with yerrorlines lt 1 dt 2 pt 6 title 'optique, p99 frame', \
     '' using 1:8:9:10 with yerrorlines lt 6 title 'ready/go baseline, median', \
     '' using 1:11:12:13 with yerrorlines lt 6 dt 2 pt 6 title 'ready/go baseline, p99'
set title 'Present skew: latest − earliest node (from 2 nodes)'
set ylabel 'skew (µs)'
plot data using 1:14:15:16 with yerrorlines lt 4 title 'median frame', \
     '' using 1:17:18:19 with yerrorlines lt 4 dt 2 pt 10 title 'p99 frame'
unset multiplot
