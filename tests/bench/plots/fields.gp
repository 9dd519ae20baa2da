# Colour fields (series.py fields): one block per wall (640×360, 1056×594); rows
# per method (one moment per frame, per-field at 1 and at 4 samples per pixel);
# columns method, draw ms (median, min, max), ratio (median, min, max), fringe px,
# PSNR_Y dB.
width = 1200; height = 480
load dir.'/style.gp'
set multiplot layout 1,2 title "Single-chip DLP projector: cost of drawing each colour field for its moment, against what a tracking eye sees"
method(i) = i == 0 ? 'one moment per frame' : i == 1 ? 'per-field, 1 sample/px' : 'per-field, 4 samples/px'
set xlabel 'draw time ÷ one moment per frame (median over runs, bars min–max)'
set offsets graph 0.08, graph 0.08, graph 0.1, graph 0.1
set title 'PSNR_Y against the ideal, around the tracked square'
set ylabel 'PSNR_Y (dB)'
set key bottom right
plot for [m = 0:2] data index 0 using ($1 == m ? $5 : NaN):9:6:7 with xerrorbars lt (m + 1) pt 7 title method(m).', 3.6 px/frame', \
     for [m = 0:2] data index 1 using ($1 == m ? $5 : NaN):9:6:7 with xerrorbars lt (m + 1) pt 5 title method(m).', 6 px/frame'
set title "Colour fringe: spread of the channels' edges across the motion"
set ylabel 'fringe (px)'
set key top right
plot for [m = 0:2] data index 0 using ($1 == m ? $5 : NaN):8:6:7 with xerrorbars lt (m + 1) pt 7 title method(m).', 3.6 px/frame', \
     for [m = 0:2] data index 1 using ($1 == m ? $5 : NaN):8:6:7 with xerrorbars lt (m + 1) pt 5 title method(m).', 6 px/frame'
unset multiplot
