// The report's script (see report_script.h).
#include "report_script.h"

namespace rvr::report {

const char* const kScript = R"(
(function () {
  var range = document.getElementById('flip-range');
  var upper = document.getElementById('flip-top');
  var button = document.getElementById('flip-button');
  if (!range || !upper || !button) return;
  function show(v) { upper.style.clipPath = 'inset(0 0 0 ' + v + '%)'; }
  range.addEventListener('input', function () { show(range.value); });
  button.addEventListener('click', function () {
    range.value = Number(range.value) < 50 ? 100 : 0;
    show(range.value);
  });
  show(range.value);
})();
)";

}  // namespace rvr::report
