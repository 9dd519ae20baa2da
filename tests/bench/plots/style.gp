# Shared look of the benchmark plots. Callers set `data` (series.py's output),
# `out` (the PNG) and `width`, `height` before loading this.
set encoding utf8
set terminal pngcairo size width, height noenhanced font 'DejaVu Sans,11' linewidth 1.5
set output out
set datafile missing 'NaN'
set grid back lc rgb '#dddddd' lw 1
set border 3 lc rgb '#444444'
set tics nomirror out
set key top left box opaque samplen 2 spacing 1.1
# One colour per method or series, the same in every plot.
set linetype 1 lc rgb '#1f77b4' pt 7 ps 0.9
set linetype 2 lc rgb '#ff7f0e' pt 5 ps 0.9
set linetype 3 lc rgb '#2ca02c' pt 9 ps 1.0
set linetype 4 lc rgb '#d62728' pt 11 ps 1.0
set linetype 5 lc rgb '#9467bd' pt 13 ps 1.0
set linetype 6 lc rgb '#7f7f7f' pt 6 ps 0.9
