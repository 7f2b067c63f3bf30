// Figure export drawn by the browser itself (plotly.js is served by the lab; nothing is fetched elsewhere).
window.dash_clientside = Object.assign({}, window.dash_clientside, {
    lab: {
        saveImage: function (clicks, id) {
            var holder = document.querySelector('[data-figure="' + id.figure + '"] .js-plotly-plot');
            if (!clicks || !holder || !window.Plotly) {
                return window.dash_clientside.no_update;
            }
            window.Plotly.downloadImage(holder, {format: id.format, filename: id.figure, scale: id.format === 'png' ? 2 : 1});
            return 'saved as ' + id.format.toUpperCase();
        }
    }
});
