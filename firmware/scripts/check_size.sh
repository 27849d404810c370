#!/bin/sh
# Prints the flash/RAM use of a firmware image and fails over budget.
# Usage: check_size.sh arm-none-eabi-size IMAGE.elf FLASH_BUDGET RAM_BUDGET
set -eu
line=$("$1" "$2" | tail -n 1)
text=$(echo "$line" | awk '{print $1}')
data=$(echo "$line" | awk '{print $2}')
bss=$(echo "$line" | awk '{print $3}')
flash=$((text + data))
ram=$((data + bss))
echo "$(basename "$2"): flash $flash bytes (budget $3), RAM $ram bytes (budget $4; stack not counted)"
[ "$flash" -le "$3" ] || { echo "FAIL: flash over budget"; exit 1; }
[ "$ram" -le "$4" ] || { echo "FAIL: RAM over budget"; exit 1; }
