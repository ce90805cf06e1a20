#!/bin/sh
# h100_round.sh OUT [GROUPS]: the H100 figures of issues 29, 31 and 33, side
# by side: run from the repository root on the device, with build-h100 from
# h100_prepare.sh plus packs/w8 and packs/w256 (gen_world --textures
# [--view 14 | --only 14] D 32 8 1024); tests/bench/HISTORY.md has them.
# GROUPS (default all): frames ug presence preview first shadow look (look
# needs packs/colorado_nofp, colorado built with nodes/footprint.sg's
# filtering off, as run.sh's look group makes it).
set -u
O=$1
G=${2:-frames ug presence preview first shadow}
B=build-h100
SB=$B/tests/splatbench
P=$B/packs
H="--size 1920x1080 --frames 20 --warmup 2"
col=$P/colorado
run() { name=$1; shift; timeout 150 "$SB" render --csv "$O/$name.csv" "$@" > "$O/$name.log" 2>&1 || echo "FAILED $name ($?)"; }
has() { case " $G " in *" $1 "*) return 0;; esac; return 1; }
if has frames; then
    for round in 1 2; do
        # round 2 also prints, after the timed frames, the layer efficiency
        # predicted for 8/32/64 lanes and other pixel orders (--lanes,
        # bench_lanes.c: "lanes" lines in the .log; measured beside it),
        # and times beside s the tiles classified in 4x4 blocks (b: the same
        # picture, lists in block order), pixel sorting by 16 tiles (s16)
        # and both (s16b: a sorting workgroup's 16 tiles a 4x4 block)
        L=; [ $round = 2 ] && L="--lanes --variant b=screen,tiles=blocks --variant s16=screen,sort=16 --variant s16b=screen,sort=16,tiles=blocks"
        for path in topdown grazing; do
            run r${round}_$path --pack $col --scene colorado --path $path --variant s=screen $H $L
        done
        for pre in trinidad valley; do
            run r${round}_$pre --pack $col --scene colorado --path ground --start-preset $pre --variant s=screen $H $L
        done
        run r${round}_meadow --pack $col --scene colorado --path ground --start-preset meadow --variant s=screen --variant ug=screen,ug $H
    done
    run r2_4k --pack $col --scene colorado --path topdown --variant s=screen --size 3840x2160 --frames 20 --warmup 2 \
        --lanes --variant b=screen,tiles=blocks --variant s16=screen,sort=16 --variant s16b=screen,sort=16,tiles=blocks
    run r2_blanca --pack $col --scene colorado --path ground --start 45000,47087,1,0 --variant s=screen $H
fi
if has ug; then
    U="--variant s=screen --variant ug=screen,ug --variant ug300=screen,ug,ugradius=300 --variant ug400t=screen,ug,ugradius=400,ugthin=1000 --variant ug450t=screen,ug,ugradius=450,ugthin=1000 --variant ug400tc=screen,ug,ugradius=400,ugthin=1000,ugcompute=1 --variant ug450tc=screen,ug,ugradius=450,ugthin=1000,ugcompute=1"
    run ug_walk --pack $col --scene colorado --path ground --start-preset meadow $U $H
    run ug_stand --pack $col --scene colorado --path ground --start-preset meadow $U --size 1920x1080 --frames 1 --warmup 3
fi
has presence && run presence --pack $P/w8 --scene world --path preset --start-preset biome --variant w8=screen --variant w256=screen,pack=$P/w256 --variant w8b=screen --variant w256b=screen,pack=$P/w256 $H
if has preview; then
    for pre in valley trinidad; do
        run preview_$pre --pack $col --scene colorado --path ground --start-preset $pre --variant full=screen --variant half=screen,preview=2 --variant quarter=screen,preview=4 $H
    done
    run preview_topdown --pack $col --scene colorado --path topdown --variant full=screen --variant half=screen,preview=2 --variant quarter=screen,preview=4 $H
fi
if has look && [ -d $P/colorado_nofp ]; then
    L="--variant on=screen --variant no_footprint=screen,pack=$P/colorado_nofp"
    for p in topdown grazing; do
        run look_$p --pack $col --scene colorado --path $p $L $H
    done
    run look_valley --pack $col --scene colorado --path ground --start-preset valley $L $H
fi
has shadow && { timeout 120 $SB shadow --pack $col --runs 5 > $O/shadow.log 2>&1 || echo "FAILED shadow"; }
if has first; then
    for pk in colorado w256; do
        [ -d $P/$pk ] || continue
        KINDS="screen screen,async screen,async+uber" timeout 300 bash tests/bench/first_picture.sh $SB $P/$pk 1920x1080 $pk topdown
    done > $O/first.txt 2>&1
fi
exit 0
