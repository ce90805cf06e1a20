# plots.gp — out/bench plots (run by run.sh inside out/bench, which has
# written the .dat files next to the CSVs):
#   pareto_*.png      speed–accuracy scatter of one knob group with its
#                     Pareto front (no other variant both faster and closer)
#   ratios.png        reference / composite, flat / composite, uber /
#                     composite GPU time ratios with the speed targets
#   compile_scaling.png  analysis cost per texel vs heightfield texels, and
#                     compile phases vs material count
set terminal pngcairo size 900,600 noenhanced font ",10"
set datafile separator whitespace
set grid
set key outside right top

do for [f in system("ls knob_*.dat 2>/dev/null")] {
    base = f[1:strlen(f) - 4]
    set output "pareto_" . base[6:] . ".png"
    set title base[6:] . ": GPU ms per frame vs mean abs error (against the group's reference)"
    set xlabel "GPU ms per frame (median)"
    set ylabel "mean abs error (log; reference drawn at 1e-7)"
    set logscale y
    plot f using 2:(($3) > 1e-7 ? $3 : 1e-7) with points pt 7 ps 1.5 title "variants", \
         f using 2:(($3) > 1e-7 ? $3 : 1e-7):1 with labels offset 1,1 notitle, \
         "pareto_" . base[6:] . ".dat" using 2:(($3) > 1e-7 ? $3 : 1e-7) with linespoints lw 2 title "Pareto front"
    unset logscale y
}

if (system("test -s shading.dat && echo y") eq "y") {
    set output "shading.png"
    set key inside top right
    unset xlabel
    set title "Screen-space shading: forward GPU ms beside the screen path's passes (same frames)"
    set style data histograms
    set style histogram rowstacked
    set style fill solid 0.8 border -1
    set boxwidth 0.4
    set xtics rotate by -30
    set ylabel "GPU ms per frame"
    set yrange [0:*]
    plot "shading.dat" using 2:xtic(1) title "forward" lc rgb "#999999", \
         newhistogram "" at 0.45, \
         "" using 3 title "screen: depth" lc rgb "#1f77b4", \
         "" using 4 title "classification" lc rgb "#ff7f0e", \
         "" using 5 title "shading" lc rgb "#2ca02c", \
         "" using 6 title "rest (barriers, copies)" lc rgb "#d62728"
    set style data points
    set style fill empty
    set xtics norotate
    set yrange [*:*]
    set key outside right top
}

if (system("test -s ratios.dat && echo y") eq "y") {
    set output "ratios.png"
    set key inside top right
    unset xlabel
    set title "GPU time ratios, measured side by side on the same frames (higher = composite wins)"
    set style data histograms
    set style histogram clustered gap 1
    set style fill solid 0.8 border -1
    set boxwidth 0.9
    set xtics rotate by -30
    set ylabel "ratio"
    set yrange [0:*]
    plot "ratios.dat" using 2:xtic(1) title "multipass / composite (target 4)", \
         "" using 3 title "flat / composite (target 1.7, colorado)", \
         "" using 4 title "uber / composite (target 1.3)", \
         4 with lines dt 2 lc rgb "black" notitle, 1.7 with lines dt 3 lc rgb "black" notitle, \
         1.3 with lines dt 4 lc rgb "black" notitle
    set style data points
    set style fill empty
    set xtics norotate
    set yrange [*:*]
    set key outside right top
}

set output "compile_scaling.png"
set key inside top left
set multiplot layout 1,2 title "splatc build scaling"
set title "analysis vs heightfield texels"
set xlabel "texels (millions)"
set ylabel "ns per texel; analysis time / 10 ms"
set logscale x
plot "scale_hf.dat" using ($1/1e6):2 with linespoints lw 2 title "analysis ns/texel", \
     "" using ($1/1e6):3 with linespoints lw 2 title "analysis time (10 ms units)"
unset logscale x
set title "compile phases vs material count (no cache)"
set xlabel "materials"
set ylabel "seconds"
plot "scale_mat.dat" using 1:3 with linespoints lw 2 title "codegen", \
     "" using 1:4 with linespoints lw 2 title "glslang", \
     "" using 1:5 with linespoints lw 2 title "total", \
     "" using 1:($2/100) with linespoints lw 2 title "combinations / 100"
unset multiplot
