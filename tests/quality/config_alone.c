/* include/foc/config.h on its own, for the static analysis of its macro
 * definitions (tests/quality/static.sh, unit `config`). */
#include "foc/config.h"
