// The pages' stylesheet (see stylesheet.h).
#include "rvr/present/stylesheet.h"

namespace rvr::present {

// The page, its headings and notes; tables; figures, legends and swatches; the charts (svg.chart,
// chart_axes.h) and their marks: the timing chart's bars, the study's log-log charts.
const char* const kStylesheet = R"(
body{font:15px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:0;
  background:#f6f7f9;color:#1d2330}
main{max-width:1400px;margin:0 auto;padding:24px} main.reading{max-width:1100px}
h1{font-size:24px;margin:0 0 4px} h2{font-size:18px;margin:30px 0 10px;
  border-bottom:1px solid #d8dce3;padding-bottom:4px} h3{font-size:16px;margin:22px 0 8px}
pre.cmd{background:#1d2330;color:#e8ecf3;padding:10px 12px;border-radius:6px;
  overflow-x:auto;white-space:pre-wrap;word-break:break-all}
.meta span{display:inline-block;margin-right:18px;color:#4a5366}
.badges{margin:10px 0}
.badge{display:inline-block;padding:3px 10px;border-radius:12px;margin:0 6px 6px 0;
  font-size:13px}
.good{background:#d9f2e1;color:#135c2c;font-weight:600}
.bad{background:#fbdcdc;color:#8a1616;font-weight:600}
.neutral{background:#e3e8f0;color:#2b3447;font-weight:600}
.warn{background:#fff4d6;border:1px solid #e6b400;border-left:6px solid #e6b400;
  padding:10px 14px;border-radius:6px;margin:14px 0}
.warn h2{border:0;margin:0 0 6px;padding:0}
p.small{color:#4a5366;font-size:13px}
details{margin:6px 0} summary{cursor:pointer;color:#2b3447}
footer{margin-top:30px;color:#7a8394;font-size:12px}
button{font:inherit;font-size:13px;padding:2px 10px;border-radius:4px;
  border:1px solid #9aa3b5;background:#fff;cursor:pointer}
table{border-collapse:collapse;background:#fff;box-shadow:0 1px 3px rgba(0,0,0,.12);
  border-radius:6px;overflow:hidden;margin-bottom:8px;font-size:14px}
th,td{padding:5px 11px;border-bottom:1px solid #e6e9ef;text-align:left;vertical-align:top}
th{background:#eef1f6;font-weight:600} td.num{text-align:right;font-variant-numeric:tabular-nums;
  white-space:nowrap}
.scroll{overflow-x:auto;max-width:100%} .nowrap{white-space:nowrap}
td.why{color:#4a5366;font-size:13px;max-width:560px}
table.timings td:first-child{white-space:nowrap}
details.more-outliers{margin:0 0 8px} details.more-outliers summary{margin-bottom:6px}
ul.coefs{margin:0;padding-left:16px} dl.machine{display:grid;grid-template-columns:max-content 1fr;
  gap:3px 14px;margin:0} dl.machine dt{font-weight:600} dl.machine dd{margin:0}
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(360px,1fr));gap:16px}
figure{margin:0 0 14px;background:#fff;padding:10px;border-radius:6px;
  box-shadow:0 1px 3px rgba(0,0,0,.12);min-width:0}
.grid figure{margin:0;padding:8px}
figure img{display:block;width:100%;height:auto;image-rendering:pixelated}
figcaption{font-size:13px;color:#4a5366;margin-top:6px}
.marked{position:relative}
.marked svg.marks{position:absolute;left:0;top:0;width:100%;height:100%;pointer-events:none}
.flip{position:relative;display:block;width:100%;user-select:none}
.flip img{display:block;width:100%;height:auto;image-rendering:pixelated}
.flip img.top{position:absolute;left:0;top:0}
.flipctl{display:flex;align-items:center;gap:10px;margin-top:6px;font-size:13px}
.flipctl input{flex:1}
.sw{display:inline-block;width:11px;height:11px;border:1px solid #9aa3b5;border-radius:2px;
  vertical-align:-1px;margin-right:5px}
.key{display:block;padding-left:17px;text-indent:-17px}
.legend{display:flex;flex-wrap:wrap;gap:6px 18px;margin:8px 0 2px;font-size:13px;color:#4a5366}
.legend svg{vertical-align:-2px;margin-right:5px}
b.tag{display:inline-block;min-width:16px;height:16px;border-radius:8px;border:1.2px solid #8a5a00;
  text-align:center;font-size:11px;line-height:16px;color:#6b4600;margin-right:3px}
svg.bar{display:block;margin-top:4px;font-size:11px;fill:#4a5366}
figure.chart-figure{max-width:1100px}
svg.chart{display:block;width:100%;height:auto;font-size:13px}
svg.chart text:not([fill]){fill:#1d2330} svg.chart .tick{fill:#4a5366;font-size:12px}
svg.chart .plot{fill:#fff;stroke:#9aa3b5}
svg.chart .gridline{stroke:#d8dce3} svg.chart .minor{stroke:#eef0f4}
svg.chart .axis-label{font-size:13px;fill:#2b3447}
svg.chart text.name{font-weight:600} svg.chart text.seg{font-size:11px}
svg.chart .unmeasured{fill:#eceef2}
svg.chart .unmeasured-label{fill:#7a8394;font-size:12px}
svg.chart .model{fill:none;stroke-width:2}
svg.chart .model-label{font-size:12px;font-weight:600}
svg.chart .spread{stroke-width:1.6}
svg.chart .mark{stroke:#fff;stroke-width:1}
svg.chart .ci-band{fill:#f0a500}
svg.chart .crossover-line{stroke:#8a5a00;stroke-width:1.5}
svg.chart .extrapolated .crossover-line{stroke:#7a8394;stroke-dasharray:4 3}
svg.chart .crossover-tag{fill:#fff;stroke:#8a5a00;stroke-width:1.2}
svg.chart .crossover-label{font-size:11px;font-weight:600;fill:#6b4600}
svg.chart .extrapolated .crossover-tag{stroke:#7a8394;stroke-dasharray:3 2}
svg.chart .extrapolated .crossover-label{fill:#4a5366}
)";

}  // namespace rvr::present
