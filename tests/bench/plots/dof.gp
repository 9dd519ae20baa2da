# Depth of field by a focused and a defocused projector (series.py dof).
# Block 0: b, PSNR away from focus for all-in-focus, pair 16-bit, pair 8-bit,
# gather (normalized). Block 1: object c_r, pair's gain; block 2: gains below the floor.
width = 1200; height = 480
load dir.'/style.gp'
set multiplot layout 1,2 title "Depth of field by two stacked projectors against the ideal per-pixel blur"
set title 'Pixels away from focus, against the focal depth'
set logscale x 10
set xrange [0.9:11]
set xtics (1, 1.5, 2, 3, 5, 8, 10)
set xlabel 'focal depth b (m)'
set ylabel 'PSNR vs ideal (dB)'
set key bottom left
plot data index 0 using 1:2 with linespoints lt 6 title 'all in focus (the render)', \
     '' index 0 using 1:3 with linespoints lt 1 title 'projector pair, 16-bit signal', \
     '' index 0 using 1:4 with linespoints lt 1 dt 2 pt 4 title 'projector pair, 8-bit', \
     '' index 0 using 1:5 with linespoints lt 2 title 'gather DOF (normalized)'
unset logscale x
set xrange [0:1]
set xtics 0.25
set title "The pair's gain per object and focal depth"
set xlabel "object's relative circle of confusion c_r"
set ylabel 'pair − all in focus (dB)'
set yrange [-16:24]
set key top left
plot 0 with lines lc rgb '#888888' dt 3 notitle, \
     data index 1 using 1:2 with points lt 1 title 'object at one b', \
     '' index 2 using 1:2 with points lt 4 pt 11 title 'below −15 dB (ideal blur under ½ px)'
unset multiplot
