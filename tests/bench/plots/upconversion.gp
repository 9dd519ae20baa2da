# Frame-rate up-conversion (series.py upconversion): one block per way in the
# bench's order (0 average at 4:1, the scene set only; 1–4 motion interpolated at 2, 3, 4, 6; 5–8
# motion extrapolated at 2, 3, 4, 6; 9, 10 interpolated and extrapolated at 4:1 with the key frames
# spread), one row per scene (0–8 the paper's set at
# 320×240, 9 many-lights at 1280×720); columns scene, cost per display frame ÷
# every frame drawn (median, min, max over runs), PSNR_Y dB of the frames between.
width = 1200; height = 660
load dir.'/style.gp'
set linetype 9 lc rgb '#17becf' pt 7 ps 0.9  # eleven ways: style.gp's colours wrap at eight
set linetype 10 lc rgb '#e377c2' pt 7 ps 0.9
set linetype 11 lc rgb '#bcbd22' pt 7 ps 0.9
set title "Frame-rate up-conversion: error against cost (● the paper's scenes, ▲ many-lights 1280×720)"
way(b) = b == 9 ? 'interpolated 4:1, spread' : b == 10 ? 'extrapolated 4:1, spread' : b == 0 ? 'average 4:1' : b <= 4 ? sprintf('interpolated %d:1', b == 1 ? 2 : b == 2 ? 3 : b == 3 ? 4 : 6) : sprintf('extrapolated %d:1', b == 5 ? 2 : b == 6 ? 3 : b == 7 ? 4 : 6)
set xlabel 'cost per display frame ÷ drawing every frame (median over runs, bars min–max)'
set ylabel 'PSNR_Y of the frames between, as displayed (dB)'
set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05
set bmargin 8
set key outside bottom center horizontal maxcols 5 font ',9'
plot for [b = 0:10] data index b using ($1 < 9 ? $2 : NaN):5:3:4 with xerrorbars lt (b + 1) pt 7 title way(b), \
     for [b = 1:10] data index b using ($1 == 9 ? $2 : NaN):5:3:4 with xerrorbars lt (b + 1) pt 9 ps 1.6 notitle
