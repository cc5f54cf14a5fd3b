/* tests/package: the least program against the stack and product.h, linked
 * through whatever the test gives it (pkg-config, add_subdirectory). */
#include "co_incl.h"
#include "product.h"

int main(void)
{
    /* 370 deg is 10 deg (incl.c); a product without a config has no rate
     * (bitrates.c). */
    static const product_t none = {.id = "none"};
    return co_incl_wrap180(370000) == 10000 && product_kbps(&none, 3) == 0u ? 0 : 1;
}
