# scale_world.gp — the scale_world group's plots (run by scale_world.sh
# inside the bench output folder, next to scale_world.tsv):
#   scale_world.png   against the material count: combinations and the
#                     largest composite; cold build and one-material-edit
#                     rebuild; pack size; first picture (screen cold and
#                     warm, screen with async pipelines, forward); peak memory of build and
#                     viewer; the steady frame on the same camera (GPU ms,
#                     layers evaluated and needed per pixel, samples per
#                     pixel, screen and forward paths).  With
#                     scale_world_gpu.tsv beside it (tests/bench/
#                     scale_world_gpu.sh's output, the device tool's GPU at 1920x1080)
#                     its steady GPU ms join the lavapipe's and a ninth panel
#                     shows its first pictures.  Runs that timed out or
#                     failed are left out.
gpu = system("test -f scale_world_gpu.tsv && echo 1 || echo 0") + 0
set terminal pngcairo size 1500,1300 noenhanced font ",10"
set datafile separator "\t"
set datafile missing "NA"
set grid
set key inside top left
set xlabel "materials"
set logscale x 2
set xtics (8, 16, 32, 64, 128, 256)
set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05
set output "scale_world.png"
set multiplot layout 3,3 title "gen_world --textures: B biomes x 8 materials (tests/bench/scale_world.sh)"

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
     "" skip 1 using 1:21 with linespoints lw 2 pt 5 title "splatview (largest run)", \
     "" skip 1 using 1:35 with linespoints lw 1 dt 2 pt 9 title "splatbench (steady frame)"

set title "steady frame, camera 'overview' held still (GPU timestamps)"
set ylabel "ms per frame"
set logscale y
set yrange [*:*]
if (gpu) {
    plot "scale_world.tsv" skip 1 using 1:26 with linespoints lw 2 pt 7 title "lavapipe screen", \
         "" skip 1 using 1:31 with linespoints lw 2 pt 9 title "lavapipe forward", \
         "scale_world_gpu.tsv" skip 1 using 1:11 with linespoints lw 2 dt 2 pt 6 title "GPU 1920x1080 screen", \
         "" skip 1 using 1:16 with linespoints lw 2 dt 2 pt 8 title "GPU 1920x1080 forward"
} else {
    plot "scale_world.tsv" skip 1 using 1:26 with linespoints lw 2 pt 7 title "lavapipe screen", \
         "" skip 1 using 1:31 with linespoints lw 2 pt 9 title "lavapipe forward"
}
unset logscale y

set title "steady frame: work per pixel (forward: per fragment)"
set ylabel "per pixel"
set yrange [0:*]
set key inside bottom right
plot "scale_world.tsv" skip 1 using 1:27 with linespoints lw 2 pt 7 title "screen layers evaluated", \
     "" skip 1 using 1:28 with linespoints lw 1 dt 2 pt 6 title "screen layers needed", \
     "" skip 1 using 1:29 with linespoints lw 2 pt 5 title "screen samples", \
     "" skip 1 using 1:32 with linespoints lw 2 pt 9 title "forward layers evaluated", \
     "" skip 1 using 1:33 with linespoints lw 1 dt 2 pt 8 title "forward layers needed", \
     "" skip 1 using 1:34 with linespoints lw 2 pt 11 title "forward samples"

set key inside top left
set title "first picture, GPU 1920x1080 (splatbench, process wall time)"
set ylabel "seconds"
if (gpu) {
    plot "scale_world_gpu.tsv" skip 1 using 1:5 with linespoints lw 2 pt 7 title "screen, cold", \
         "" skip 1 using 1:6 with linespoints lw 2 dt 2 pt 6 title "screen, warm caches", \
         "" skip 1 using 1:7 with linespoints lw 2 pt 5 title "screen async, cold", \
         "" skip 1 using 1:9 with linespoints lw 2 pt 9 title "forward, cold", \
         "" skip 1 using 1:10 with linespoints lw 2 dt 2 pt 8 title "forward, warm caches"
} else {
    set label 2 "no scale_world_gpu.tsv\n(tests/bench/scale_world_gpu.sh)" at graph 0.5, 0.5 center
    plot "scale_world.tsv" skip 1 using 1:7 with points lc rgb "white" notitle
    unset label 2
}
unset multiplot
