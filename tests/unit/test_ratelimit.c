/* Rate limits: a burst, then the rate, per key; Retry-After that matches when a token comes
 * back; a table of keys that stays bounded under many clients without forgetting the busy
 * ones; the flag syntax. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <time.h>
#include <unistd.h>

#include "net/ratelimit.h"

static void a_burst_then_the_rate(void **state)
{
    (void)state;
    ag_ratelimit *rl = ag_ratelimit_create((ag_rate){.rate = 20, .burst = 5}, 64);
    assert_non_null(rl);
    double wait = 0;
    for (int i = 0; i < 5; i++)
        assert_int_equal(ag_ratelimit_take(rl, "addr:a", &wait), 1);
    assert_int_equal(ag_ratelimit_take(rl, "addr:a", &wait), 0);
    assert_true(wait > 0 && wait <= 1.0 / 20 + 1e-6);
    double said = wait;
    /* another key has a bucket of its own */
    assert_int_equal(ag_ratelimit_take(rl, "addr:b", &wait), 1);
    /* after the wait it said, a token is back */
    usleep((useconds_t)(said * 1e6) + 2000);
    assert_int_equal(ag_ratelimit_take(rl, "addr:a", &wait), 1);
    assert_int_equal(ag_ratelimit_take(rl, "addr:a", &wait), 0);
    ag_ratelimit_free(rl);
}

static void no_rate_allows_everything(void **state)
{
    (void)state;
    ag_ratelimit *rl = ag_ratelimit_create((ag_rate){0}, 16);
    double wait = 1;
    for (int i = 0; i < 10000; i++)
        assert_int_equal(ag_ratelimit_take(rl, "k", &wait), 1);
    assert_true(wait == 0);
    assert_int_equal(ag_ratelimit_take(NULL, "k", &wait), 1);
    ag_ratelimit_free(rl);
}

static void many_clients_keep_the_table_bounded_and_busy_keys_limited(void **state)
{
    (void)state;
    ag_ratelimit *rl = ag_ratelimit_create((ag_rate){.rate = 0.001, .burst = 3}, 64);
    double wait;
    /* a busy client empties its bucket */
    for (int i = 0; i < 3; i++)
        assert_int_equal(ag_ratelimit_take(rl, "addr:busy", &wait), 1);
    assert_int_equal(ag_ratelimit_take(rl, "addr:busy", &wait), 0);
    /* thousands of one-off clients come and go: the busy one stays empty as long as it keeps
     * asking (it is among the most recently seen) */
    char key[32];
    for (int i = 0; i < 5000; i++) {
        snprintf(key, sizeof key, "addr:10.0.%d.%d", i / 256, i % 256);
        assert_int_equal(ag_ratelimit_take(rl, key, &wait), 1);
        if (i % 16 == 0)
            assert_int_equal(ag_ratelimit_take(rl, "addr:busy", &wait), 0);
    }
    assert_int_equal(ag_ratelimit_take(rl, "addr:busy", &wait), 0);
    ag_ratelimit_free(rl);
}

static void rates_parse(void **state)
{
    (void)state;
    ag_rate r;
    assert_int_equal(ag_ratelimit_parse("200/2000", &r), 0);
    assert_true(r.rate == 200 && r.burst == 2000);
    assert_int_equal(ag_ratelimit_parse("0.5", &r), 0);
    assert_true(r.rate == 0.5 && r.burst == 0);
    assert_int_equal(ag_ratelimit_parse("0", &r), 0);
    assert_true(r.rate == 0);
    const char *bad[] = {"", "x", "-1", "5/", "5/0", "5/x", "5/2/3", "nan", "inf", "1e999"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        assert_int_equal(ag_ratelimit_parse(bad[i], &r), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_burst_then_the_rate),
        cmocka_unit_test(no_rate_allows_everything),
        cmocka_unit_test(many_clients_keep_the_table_bounded_and_busy_keys_limited),
        cmocka_unit_test(rates_parse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
