// A script ESLint must reject (tests/CMakeLists.txt): `unused` is never read.
(function () {
  "use strict";
  const unused = 1;
})();
