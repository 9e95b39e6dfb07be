/*
 * Where tools/pil finds the controller's fields in the image's RAM: this
 * file is compiled by arm-none-eabi-gcc with the image's flags (make pil)
 * and pil.py reads the table from the object.  Only for the CSV columns
 * that focsim also takes from the controller (references, estimates,
 * voltage command); the tests' oracles use the plant's true state.
 */
#include <stddef.h>
#include <stdint.h>
#include "foc/controller.h"

#define F(path) (uint16_t)offsetof(foc_ctrl_t, path)

/* sizes in the high byte: 1, 2 or 4 */
#define E(path) (uint32_t)(F(path) | ((uint32_t)sizeof(((foc_ctrl_t *)0)->path) << 16))

const uint32_t pil_ctrl_layout[] __attribute__((used)) = {
    0x50494C31u, /* "PIL1" */
    E(state), E(faults.first), E(startup.speed), E(speed_ctrl.ramped),
    E(est.est_speed), E(est.est_theta), E(i_ref.d), E(i_ref.q), E(v_dq.d),
    E(v_dq.q), (uint32_t)sizeof(foc_ctrl_t),
};
