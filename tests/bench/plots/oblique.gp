# Single pass vs two passes per oblique projector (series.py oblique): one block
# per projector (left, centre, right); rows single pass, two passes at the densest
# pitch, two passes with as many texels as pixels; columns method, time (median,
# min, max over runs), PSNR.
width = 900; height = 560
load dir.'/style.gp'
set title "Oblique projectors: frame time against image quality\n(time: median over runs, bars min–max; PSNR against a 4×-supersampled render, median over frames)"
set xlabel 'frame time (ms, llvmpipe)'
set ylabel 'PSNR (dB)'
set key bottom right
set offsets graph 0.05, graph 0.05, graph 0.1, graph 0.1
method(i) = i == 0 ? 'single pass' : i == 1 ? 'two passes, densest pitch' : 'two passes, texels = pixels'
plot for [p = 0:2] data index p using 2:5 with lines lc rgb '#bbbbbb' notitle, \
     for [m = 0:2] data index 0:2 using ($1 == m ? $2 : NaN):5:3:4 with xerrorbars lt (m + 1) title method(m), \
     for [p = 0:2] data index p every ::0::0 using 2:5:(p == 0 ? 'left' : p == 1 ? 'centre' : 'right') with labels offset 0, -1.2 notitle
