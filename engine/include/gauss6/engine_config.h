/* Config text of an engine behind the C ABI (gauss6/engine.h), header-only C99:
 * `key=value` items separated by ';' or white space ("sim_period=2",
 * "inner=lib.so;fault=nan;at=1.0"). The shipped engines read their config with it
 * and refuse a key they do not know (a misspelt key is an error naming it, never
 * a silently ignored setting); an engine of a third party may use it too.
 */
#ifndef GAUSS6_ENGINE_CONFIG_H
#define GAUSS6_ENGINE_CONFIG_H

#include <stdio.h>
#include <string.h>

static inline int gauss6_config_separator(char c) {
  return c == ';' || c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* The next item of config from *p: its key [*key, *key + *key_len) and value
 * [*value, *value + *value_len); 0 when there is none left. */
static inline int gauss6_config_next(const char** p, const char** key, size_t* key_len, const char** value,
                              size_t* value_len) {
  const char* s = *p;
  while (*s && gauss6_config_separator(*s)) ++s;
  if (!*s) return 0;
  const char* end = s;
  while (*end && !gauss6_config_separator(*end)) ++end;
  const char* eq = s;
  while (eq < end && *eq != '=') ++eq;
  *key = s;
  *key_len = (size_t)(eq - s);
  *value = eq < end ? eq + 1 : end;
  *value_len = eq < end ? (size_t)(end - eq - 1) : 0;
  *p = end;
  return eq < end ? 1 : -1; /* -1: an item without '=' */
}

/* 0 when every item of config is `key=value` with key one of keys (NULL-terminated);
 * otherwise 1, with "<engine>: config item '<item>': expected key=value with key one
 * of ..." in error. */
static inline int gauss6_config_check(const char* config, const char* const* keys, const char* engine, char* error,
                               size_t error_size) {
  const char *p = config ? config : "", *key, *value;
  size_t key_len, value_len;
  int status;
  while ((status = gauss6_config_next(&p, &key, &key_len, &value, &value_len)) != 0) {
    int known = 0;
    for (const char* const* k = keys; status > 0 && *k; ++k)
      if (strlen(*k) == key_len && strncmp(*k, key, key_len) == 0) known = 1;
    if (!known) {
      if (error && error_size) {
        int n = snprintf(error, error_size, "%s: config item '%.*s': expected key=value with key one of", engine,
                         (int)(status > 0 ? key_len + 1 + value_len : key_len), key);
        for (const char* const* k = keys; *k && n >= 0 && (size_t)n < error_size; ++k)
          n += snprintf(error + n, error_size - (size_t)n, " %s", *k);
      }
      return 1;
    }
  }
  return 0;
}

/* The value of key in config into out (NUL-terminated, size n); 1 when present and
 * it fits, else 0 (out unchanged). */
static inline int gauss6_config_value(const char* config, const char* name, char* out, size_t n) {
  const char *p = config ? config : "", *key, *value;
  size_t key_len, value_len;
  int status;
  while ((status = gauss6_config_next(&p, &key, &key_len, &value, &value_len)) != 0) {
    if (status > 0 && strlen(name) == key_len && strncmp(name, key, key_len) == 0) {
      if (value_len + 1 > n) return 0;
      memcpy(out, value, value_len);
      out[value_len] = 0;
      return 1;
    }
  }
  return 0;
}

#endif /* GAUSS6_ENGINE_CONFIG_H */
