# The units of the board's register map (gateware/board/), for the scripts
# that build it (build-bitstream, build-board-sim); sourced, not run.
#   board_flags  cbvh_board_top's HAS_* parameters, in unit id order
#   board_names  the units' names (as in vector files), board_ids their ids
#   board_units LIST ME   sets board_on[i] = 1 for each unit of LIST (names or
#                ids, comma-separated; "none" = no unit, "all" = every unit); a bad entry exits 2
#                with one line naming it, prefixed by ME
board_flags=(HAS_ESTIMATOR HAS_COMPRESSOR HAS_DECODER HAS_NP_ENCODER HAS_NP_DECODER HAS_RAY_BOX HAS_RAY_TRI
             HAS_QBVH_STACK HAS_RAY_SPHERE)
board_names=(scale_estimate axis_compress axis_decode nodepair_encode nodepair_decode ray_box ray_triangle
             qbvh_stack ray_sphere)
board_ids=(1 2 3 4 5 6 7 8 9)

board_units() {
    local list=$1 me=$2 u i hit
    board_on=()
    for i in "${!board_names[@]}"; do board_on[$i]=0; done
    [ "$list" = none ] && return 0
    if [ "$list" = all ]; then
        for i in "${!board_names[@]}"; do board_on[$i]=1; done
        return 0
    fi
    [ -n "$list" ] || { echo "$me: --units expects a comma-separated list of units (or none)" >&2; exit 2; }
    IFS=, read -r -a req <<<"$list"
    for u in "${req[@]}"; do
        hit=-1
        for i in "${!board_names[@]}"; do
            if [ "$u" = "${board_names[$i]}" ] || [ "$u" = "${board_ids[$i]}" ]; then hit=$i; fi
        done
        [ $hit -ge 0 ] ||
            { echo "$me: unknown unit '$u' (names: ${board_names[*]}; or ids; or none)" >&2; exit 2; }
        board_on[$hit]=1
    done
}
