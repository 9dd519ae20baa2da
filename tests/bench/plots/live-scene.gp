# The live scene against the instances an application moves each frame
# (series.py live-scene). Block 0, one row per count: moved, then (median, min,
# max over runs) of the barrier round median, the scene bytes a frame
# (FrameBegin and staged edits) and the snapshot bytes. Block 1: the runs without an application, at x = 0.5.
width = 1200; height = 480
load dir.'/style.gp'
set multiplot layout 1,2 title "Live scene: an application moving instances every frame (null-render nodes, loopback): median over runs, bars min–max"
set logscale x 10
set xrange [0.3:30000]
set xtics ('none' 0.5, 1, 10, 100, 1000, 10000)
set format y '%g'
set xlabel 'instances moved each frame'
set ylabel 'time (µs)'
set logscale y 10
set title 'Barrier round, median frame'
plot data index 0 using 1:2:3:4 with yerrorlines lt 1 title 'with the application', \
     '' index 1 using 1:2:3:4 with yerrorbars lt 6 title 'no application'
set title 'Bytes each node is sent a frame'
set ylabel 'bytes'
plot data index 0 using 1:5:6:7 with yerrorlines lt 2 title 'FrameBegin and staged edits (the change)', \
     '' index 0 using 1:8:9:10 with yerrorlines lt 4 dt 2 title 'snapshot of the whole state', \
     '' index 1 using 1:5:6:7 with yerrorbars lt 6 title 'FrameBegin, no application'
unset multiplot
