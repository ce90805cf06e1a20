# scale_world.gp — the scale_world group's plots (run by scale_world.sh
# inside the bench output folder, next to scale_world.tsv):
#   scale_world.png   against the material count: combinations and the
#                     largest composite; cold build and one-material-edit
#                     rebuild; pack size; first picture (screen cold and
#                     warm, screen with async pipelines, forward); peak memory of build and
#                     viewer.  Runs that timed out or failed are left out.
set terminal pngcairo size 1500,900 noenhanced font ",10"
set datafile separator "\t"
set datafile missing "NA"
set grid
set key inside top left
set xlabel "materials"
set logscale x 2
set xtics (8, 16, 32, 64, 128, 256)
set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05
set output "scale_world.png"
set multiplot layout 2,3 title "gen_world --textures: B biomes x 8 materials (tests/bench/scale_world.sh)"

set title "analysis: what the pixels need"
set ylabel "count"
set logscale y
plot "scale_world.tsv" skip 1 using 1:3 with linespoints lw 2 pt 7 title "combinations (leaf cells)", \
     "" skip 1 using 1:4 with linespoints lw 2 pt 5 title "pipelines built", \
     "" skip 1 using 1:5 with linespoints lw 2 pt 9 title "largest composite (layers)", \
     "" skip 1 using 1:6 with linespoints lw 2 dt 2 pt 1 title "largest leaf overlap (layers)"
unset logscale y

set title "splatc build -j 2"
set ylabel "seconds"
set yrange [0:*]
plot "" skip 1 using 1:7 with linespoints lw 2 pt 7 title "cold (empty cache)", \
     "" skip 1 using 1:9 with linespoints lw 1 pt 1 title "  of which glslang", \
     "" skip 1 using 1:10 with linespoints lw 1 pt 2 title "  of which spirv-val", \
     "" skip 1 using 1:11 with linespoints lw 2 pt 5 title "one-material edit (warm cache)"

set key inside bottom right
set title "one-material edit: shaders recompiled"
set ylabel "shaders"
plot "" skip 1 using 1:12 with linespoints lw 2 pt 7 title "recompiled", \
     "" skip 1 using 1:14 with linespoints lw 2 dt 2 pt 1 title "combinations holding the material"

set key inside top left
set title "pack size (du -sb)"
set ylabel "MB"
plot "" skip 1 using 1:15 with linespoints lw 2 pt 7 title "pack"

set title "first picture, lavapipe headless (process wall time)"
set ylabel "seconds"
if (exists("noview")) {
    # scale_world.sh --no-view: no pictures taken, an empty panel
    set label 1 "no pictures (--no-view)" at graph 0.5, 0.5 center
    plot "" skip 1 using 1:7 with points lc rgb "white" notitle
    unset label 1
} else {
    plot "" skip 1 using 1:18 with linespoints lw 2 pt 7 title "screen (all pipelines first)", \
         "" skip 1 using 1:25 with linespoints lw 2 dt 2 pt 6 title "screen, warm caches (second run)", \
         "" skip 1 using 1:19 with linespoints lw 2 pt 5 title "screen, async pipelines", \
         "" skip 1 using 1:20 with linespoints lw 2 pt 9 title "forward"
}

set title "peak resident memory"
set ylabel "MB"
plot "" skip 1 using 1:8 with linespoints lw 2 pt 7 title "splatc build", \
     "" skip 1 using 1:21 with linespoints lw 2 pt 5 title "splatview (largest run)"
unset multiplot
