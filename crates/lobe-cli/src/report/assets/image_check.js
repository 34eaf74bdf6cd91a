window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var bad = imgs.filter(function (i) { return !(i.complete && i.naturalWidth > 0); });
  var out = document.getElementById('image-check');
  if (bad.length === 0) {
    out.textContent = 'ok ' + imgs.length + '/' + imgs.length + ' images loaded';
  } else {
    out.textContent = 'FAILED ' + (imgs.length - bad.length) + '/' + imgs.length +
      ' images loaded; missing: ' + bad.map(function (i) { return i.getAttribute('src'); }).join(' ');
  }
});
