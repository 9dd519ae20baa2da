# Lights split across stacked nodes (series.py lighting): one block per scene
# (20, 50, 100 lights); columns nodes, speed-up (median, min, max over runs), PSNR.
width = 1200; height = 480
load dir.'/style.gp'
set multiplot layout 1,2 title "Lights split across stacked projectors (identical nodes)"
set xrange [0.8:4.2]
set xtics 1
set xlabel 'stacked nodes'
set title 'Speed-up: full render ÷ slowest node (median over runs, bars min–max)'
set ylabel 'speed-up'
set yrange [0:4.25]
plot x with lines lc rgb '#888888' dt 3 title 'ideal (= nodes)', \
     data index 0 using 1:2:3:4 with yerrorlines lt 1 title '20 lights', \
     '' index 1 using 1:2:3:4 with yerrorlines lt 2 title '50 lights', \
     '' index 2 using 1:2:3:4 with yerrorlines lt 4 title '100 lights'
set title 'Optical sum of 8-bit projectors vs the exact render'
set ylabel 'PSNR (dB, median over frames)'
set yrange [*:*]
set key bottom right
plot data index 0 using 1:5 with linespoints lt 1 title '20 lights', \
     '' index 1 using 1:5 with linespoints lt 2 title '50 lights', \
     '' index 2 using 1:5 with linespoints lt 4 title '100 lights'
unset multiplot
