#!/bin/sh
# Checks a linked STM32F10x image: the vector table sits at the start of
# flash, its first word is the initial stack pointer, the handlers the port
# uses are in their slots (Thumb addresses), and no printf was linked.
# Usage: check_image.sh <image.elf> [irq-count]
set -eu
elf=$1
irqs=${2:-43}
nm=arm-none-eabi-nm
fail() { echo "check_image: $*" >&2; exit 1; }

addr() { $nm "$elf" | awk -v s="$1" '$3 == s { print $1 }'; }
[ "$(addr vector_table)" = "08000000" ] || fail "vector_table is not at 0x08000000"

words=$(arm-none-eabi-objcopy -O binary -j .isr_vector "$elf" /dev/stdout | od -An -v -tx4)
count=$(echo "$words" | wc -w)
[ "$count" -eq $((16 + irqs)) ] || fail "vector table has $count entries, expected $((16 + irqs))"

slot() { echo "$words" | tr -s ' \n' '\n\n' | sed '/^$/d' | sed -n "$(($1 + 1))p"; }
thumb() { printf '%08x' $((0x$(addr "$1") | 1)); }

[ "$(slot 0)" = "$(addr _estack)" ] || fail "entry 0 is not _estack"
check() { [ "$(slot "$1")" = "$(thumb "$2")" ] || fail "entry $1 is not $2"; }
check 1 Reset_Handler
check 2 NMI_Handler
check 3 HardFault_Handler
check 15 SysTick_Handler
check $((16 + 18)) ADC1_2_IRQHandler
check $((16 + 24)) TIM1_BRK_IRQHandler
check $((16 + 25)) TIM1_UP_IRQHandler

if $nm "$elf" | grep -Eq ' [A-Za-z] _?(v?[sfn]*i?printf|_printf_.*)$'; then
    fail "printf is linked into the image"
fi
echo "check_image: vector table and handlers in place, no printf"
