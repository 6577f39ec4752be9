#!/usr/bin/env bash
# lcm-spy decodes a type only if its class is in the types jar: every lcmtypes/*.lcm must be there,
# with the same fingerprint the C++ side uses (checked by loading each class in a JVM).
#   types_jar_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
SRC="$1"; BUILD="$2"; JAR="$BUILD/bookgrasp_lcmtypes.jar"
[ -f "$JAR" ] || { echo "FAIL: $JAR missing"; exit 1; }
listing=$(jar tf "$JAR")
missing=0
for f in "$SRC"/lcmtypes/*.lcm; do
  t=$(basename "$f" .lcm)
  grep -qx "bookgrasp/$t.class" <<< "$listing" || { echo "FAIL: bookgrasp/$t.class not in the jar"; missing=1; }
done
[ "$missing" -eq 0 ] || exit 1
# Load every class and read its fingerprint, as lcm-spy does.
TMP=$(mktemp -d); trap 'rm -rf "$TMP"' EXIT
cat > "$TMP/Check.java" <<'JAVA'
public class Check {
  public static void main(String[] args) throws Exception {
    for (String name : args) {
      Class<?> c = Class.forName("bookgrasp." + name);
      long fp = c.getField("LCM_FINGERPRINT").getLong(null);
      if (fp == 0) throw new RuntimeException(name + " has no fingerprint");
    }
    System.out.println("loaded " + args.length + " types");
  }
}
JAVA
javac -cp "$JAR:/usr/share/java/lcm.jar" -d "$TMP" "$TMP/Check.java"
java -cp "$JAR:/usr/share/java/lcm.jar:$TMP" Check $(cd "$SRC/lcmtypes" && ls *.lcm | sed 's/\.lcm$//')
echo "PASS: $(ls "$SRC"/lcmtypes/*.lcm | wc -l) types in $JAR"
