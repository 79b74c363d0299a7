#!/usr/bin/env bash
# NVIDIA Texture Tools' nvcompress (Debian libnvtt-bin) on the inputs of
# compress_peers_bench, BC1 and BC4, each quality it offers; its DDS files are
# decoded by Atlas's Reference decoder for the RMSE. Not part of CI.
#
#   bench/compare_nvcompress.sh BUILD_DIR [WORK_DIR]
#
# NVTT 2.0 (Debian 12) has -fast and the default quality; -production does not exist
# there (its usage text is checked; 2.0 silently ignores unknown options). -nocuda: CPU compressor; -nomips: one level.
set -euo pipefail
build=${1:?usage: compare_nvcompress.sh BUILD_DIR [WORK_DIR]}
work=${2:-$(mktemp -d)}
peers="$build/bench/compress_peers_bench"
command -v nvcompress > /dev/null || { echo "nvcompress not found (apt-get install libnvtt-bin)" >&2; exit 1; }
[ -x "$peers" ] || { echo "$peers not built (needs libsquish-dev)" >&2; exit 1; }
mkdir -p "$work"
"$peers" --write-inputs "$work" > "$work/inputs.txt"
printf 'format\tquality\tinput\tseconds\tresult\n'
while IFS=$'\t' read -r png name; do
    case "$png" in
    *_rgb.png) fmt=bc1 ;;
    *_grey.png) fmt=bc4 ;;
    *) continue ;;
    esac
    for q in fast default production; do
        if [ "$q" = production ] && ! nvcompress 2>&1 | grep -q -- -production; then
            printf '%s\t%s\t%s\t-\tnot offered by this nvcompress (2.0 ignores the option)\n' "$fmt" "$q" "$name"
            continue
        fi
        flag=()
        [ "$q" = fast ] && flag=(-fast)
        [ "$q" = production ] && flag=(-production)
        out="$work/$(basename "$png" .png)_${fmt}_${q}.dds"
        start=$(date +%s.%N)
        if nvcompress -nocuda -nomips "${flag[@]}" "-$fmt" "$png" "$out" > "$work/nv.log" 2>&1 && [ -s "$out" ]; then
            end=$(date +%s.%N)
            printf '%s\t%s\t%s\t%.3f\t%s\n' "$fmt" "$q" "$name" "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')" "$("$peers" --rmse "$out" "$png")"
        else
            printf '%s\t%s\t%s\t-\tnot supported by this nvcompress\n' "$fmt" "$q" "$name"
        fi
    done
done < "$work/inputs.txt"
