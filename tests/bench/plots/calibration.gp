# Calibration fits of a strong oblique projector (series.py calibration).
# Block 0: points, then (median, min, max) time per fit for DLT, DLT + refinement,
# robust. Block 1: points, transfer error ÷ optimum for the same methods.
width = 1200; height = 480
load dir.'/style.gp'
set multiplot layout 1,2 title "Homography fit from projector–screen points, σ = 0.5 px noise"
set logscale xy 10
set xrange [3:300]
set xtics (4, 20, 200)
set format y '%g'
set xlabel 'calibration points'
set title 'Time per fit, no outliers (median over repeats, bars min–max)'
set ylabel 'time per fit (µs)'
plot data index 0 using 1:2:3:4 with yerrorlines lt 1 title 'DLT only', \
     '' index 0 using 1:5:6:7 with yerrorlines lt 2 title 'DLT + refinement', \
     '' index 0 using 1:8:9:10 with yerrorlines lt 3 title 'robust (RANSAC + refinement)'
set title 'Error with 10 % gross outliers'
set ylabel 'transfer error ÷ optimum (1 = best possible)'
set yrange [0.5:500]
set xrange [15:300]
set xtics (20, 200)
plot data index 1 using 1:2 with linespoints lt 1 title 'DLT only', \
     '' index 1 using 1:3 with linespoints lt 2 title 'DLT + refinement', \
     '' index 1 using 1:4 with linespoints lt 3 title 'robust (RANSAC + refinement)', \
     1 with lines lc rgb '#888888' dt 3 notitle
unset multiplot
