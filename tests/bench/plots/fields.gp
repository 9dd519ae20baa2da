# Colour fields (series.py fields): one block per scene (moving square, pinball,
# scrolling stripes at 120 Hz with three fields; the square and the pinball on the
# stereo projector used as mono, six fields in two images, and the pinball
# again with the viewer walking); rows per method in
# the bench's order (0 one moment per frame, 1 per-field at 1 sample per pixel,
# 2 per-field shipped, 3 per-field with still objects per field, 4 per-field with
# blur above the velocity threshold, 5–7 gather at 4, 8, 16 samples along the
# motion, 8 gather at 1 sample per pixel, 9 up-conversion, 10 up-conversion at 1
# sample per pixel);
# columns method, draw ms (median, min, max), ratio to one moment (median, min,
# max), ratio to per-field (median, min, max), fringe px, PSNR_Y dB, worst
# channel dB against per-field (NaN: identical).
width = 1200; height = 660
load dir.'/style.gp'
set linetype 9 lc rgb '#17becf' pt 7 ps 0.9  # eleven methods: style.gp's colours wrap at eight
set linetype 10 lc rgb '#e377c2' pt 7 ps 0.9
set linetype 11 lc rgb '#bcbd22' pt 7 ps 0.9
set multiplot layout 1,2 title "Single-chip DLP projector: each colour field at its moment, per-field or gathered from one render"
method(i) = i == 0 ? 'one moment' : i == 1 ? 'per-field 1 spp' : i == 2 ? 'per-field' : i == 3 ? 'per-field, still per field' : i == 4 ? 'per-field + blur' : i == 5 ? 'gather 4' : i == 6 ? 'gather 8' : i == 7 ? 'gather 16' : i == 8 ? 'gather 8, 1 spp' : i == 9 ? 'up-conversion' : 'up-conversion, 1 spp'
set offsets graph 0.08, graph 0.08, graph 0.1, graph 0.1
set bmargin 9
set xlabel 'draw time ÷ one moment per frame (median over runs, bars min–max)'
set title "PSNR_Y of what a tracking eye sees, against the ideal\n(■ square, ● pinball, ▲ stripes; six fields: ▼ square, ◆ pinball, ⬟ walking)"
set ylabel 'PSNR_Y (dB)'
set key outside bottom center horizontal maxcols 3 font ',9'
plot for [b = 0:5] for [m = 0:10] data index b using ($1 == m ? $5 : NaN):12:6:7 with xerrorbars lt (m + 1) pt (5 + 2 * b) title (b == 0 ? method(m) : '')
set xlabel 'draw time ÷ per-field (median over runs, bars min–max)'
set title "Against per-field's perceived image (worst channel)\n(■ square, ● pinball, ▲ stripes; six fields: ▼ square, ◆ pinball, ⬟ walking)"
set ylabel 'PSNR (dB)'
set key outside bottom center horizontal maxcols 3 font ',9'
# Rows identical to per-field have no value (NaN): per-field's own, and any
# method that gives its image to the bit. One pass per scene, each row coloured
# by its method (a method with no point in a scene would be an empty plot); the
# key from empty functions.
plot for [b = 0:5] data index b using 8:13:9:10:($1 + 1) with xerrorbars lc variable pt (5 + 2 * b) notitle, \
     for [k in "0 1 4 5 6 7 8 9 10"] NaN with points lt (k + 1) pt 5 title method(k + 0)
unset multiplot
