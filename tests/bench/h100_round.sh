#!/bin/sh
# h100_round.sh OUT: the third session's H100 figures (issues 29, 33), side by side:
# run from the repository root on the device, with build-h100 from
# h100_prepare.sh plus packs/w8 and packs/w256 (gen_world --textures
# [--view 14 | --only 14] D 32 8 1024); tests/bench/HISTORY.md has them.
set -u
O=$1
B=build-h100
SB=$B/tests/splatbench
P=$B/packs
H="--size 1920x1080 --frames 20 --warmup 2"
col=$P/colorado
run() { name=$1; shift; timeout 120 "$SB" render --csv "$O/$name.csv" "$@" > "$O/$name.log" 2>&1 || echo "FAILED $name ($?)"; }
for round in 1 2; do
    for path in topdown grazing; do
        run r${round}_$path --pack $col --scene colorado --path $path --variant s=screen $H
    done
    for pre in trinidad valley; do
        run r${round}_$pre --pack $col --scene colorado --path ground --start-preset $pre --variant s=screen $H
    done
    run r${round}_meadow --pack $col --scene colorado --path ground --start-preset meadow --variant s=screen --variant ug=screen,ug $H
done
run r2_4k --pack $col --scene colorado --path topdown --variant s=screen --size 3840x2160 --frames 20 --warmup 2
run r2_ug --pack $col --scene colorado --path ground --start-preset meadow --variant ug=screen,ug --variant ug200=screen,ug,ugradius=200 --variant ug300=screen,ug,ugradius=300 $H
run r2_presence --pack $P/w8 --scene world --path preset --start-preset biome --variant w8=screen --variant w256=screen,pack=$P/w256 --variant w8b=screen --variant w256b=screen,pack=$P/w256 $H
timeout 120 $SB shadow --pack $col --runs 5 > $O/shadow.log 2>&1 || echo "FAILED shadow"
for pk in colorado w256; do
    KINDS="screen screen,async" timeout 200 bash tests/bench/first_picture.sh $SB $P/$pk 1920x1080 $pk topdown
done > $O/first.txt 2>&1
