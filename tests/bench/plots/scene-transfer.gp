# A large scene sent to a node with an empty cache (series.py scene-transfer):
# rows method index, median MiB/s, min, max over runs.
width = 900; height = 520
load dir.'/style.gp'
set title "A 200 MiB scene over loopback to a node with an empty cache\n(median over runs, bars min–max)"
set ylabel 'MiB/s'
set yrange [0:*]
set style fill solid 0.6 border -1
set boxwidth 0.6
set xtics ('raw TCP' 0, "TCP, checked\nand stored" 1, 'optique fetch' 2, "cached copy\nchecked" 3)
set xrange [-0.6:3.6]
unset key
set bmargin 5
plot data using 1:2:3:4:(0.6) with boxerrorbars lt 1
