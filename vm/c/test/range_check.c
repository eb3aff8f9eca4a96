/* rl1_in_range (rl1vm.h) against its meaning, low <= value <= low + span written with
 * two signed comparisons, for every parameter range of rl1_param_ranges and every int16_t
 * value: on the host, and under simavr, where int has 16 bits and the unsigned
 * difference wraps at 2^16 (tests/c/test_c_range_check.py). Prints "range: <checked>
 * <wrong>". */
#include "target.h"

uint16_t target_run(void)
{
    uint32_t checked = 0, wrong = 0;
    uint8_t index;
    char line[40], *at = line;
    for (index = 0; index < RL1_PARAM_COUNT; index++) {
        const rl1_param_range *range = &rl1_param_ranges[index];
        int32_t low = rl1_flash_i16(&range->low);
        int32_t high = low + (int32_t)rl1_flash_u16(&range->span);
        int32_t value = INT16_MIN;
        for (; value <= INT16_MAX; value++) {
            bool within = low <= value && value <= high;
            checked++;
            if (rl1_in_range(range, (int16_t)value) != within) {
                wrong++;
            }
        }
    }
    at = target_decimal(at, checked);
    *at++ = ' ';
    at = target_decimal(at, wrong);
    *at++ = '\n';
    *at = 0;
    target_print("range: ");
    target_print(line);
    return (uint16_t)(wrong != 0);
}
