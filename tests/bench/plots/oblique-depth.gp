# Depth order of single-pass oblique rendering (series.py oblique-depth).
# Blocks 0–2 (yaw, diagonal rolled, askew close): θ, compression ours, paper.
# Block 3: δ (mm), worst share of wrong pixels for ours, paper, aligned.
width = 1200; height = 480
load dir.'/style.gp'
set multiplot layout 1,2 title "Depth order when one pass renders for an oblique projector (24-bit depth)"
set xlabel 'incidence θ on the wall (°)'
set ylabel 'depth compression c (< 0: order reversed)'
set title 'How much depth differences shrink at the worst pixel'
set key top right
set xrange [-2:88]
set yrange [-0.3:1.05]
plot 0 with lines lc rgb '#888888' dt 3 notitle, \
     data index 0 using 1:2 with linespoints lt 1 title 'yaw: ours', \
     '' index 0 using 1:3 with linespoints lt 1 dt 2 title "yaw: paper's third row", \
     '' index 1 using 1:2 with linespoints lt 2 title 'diagonal, rolled: ours', \
     '' index 1 using 1:3 with linespoints lt 2 dt 2 title "diagonal, rolled: paper's", \
     '' index 2 using 1:2 with linespoints lt 4 title 'askew, close: ours', \
     '' index 2 using 1:3 with linespoints lt 4 dt 2 title "askew, close: paper's"
set title 'Wrong object shown, worst frame over all series and θ'
set xlabel 'separation δ of the two quads (mm)'
set ylabel 'wrong pixels (% of counted)'
set logscale x 10
set xrange [0.007:15]
set yrange [-3:100]
set format x '%g'
set key top right
plot data index 3 using 1:2 with linespoints lt 1 title 'ours', \
     '' index 3 using 1:3 with linespoints lt 2 title "paper's third row", \
     '' index 3 using 1:4 with linespoints lt 3 title "viewer's own frustum (no oblique map)"
unset multiplot
